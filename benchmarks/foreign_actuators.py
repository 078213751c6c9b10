"""Actuators unlike the thesis's, each read with its own ema-actuator/1 document: docs/results.md.

Windows drawn by ``tests.foreign`` (an independent implementation of the model) for two drives of the
architecture with other constants (``tests.foreign.actuators``: gear ratio 320 and 800, k_T 0.12 and
0.05 N·m/A, their own inertia, gains, backlash and stops) and the thesis's, each in three conditions: in
flight (thesis-family commands, random flight conditions), on the ground without load (a pre-flight
sweep) and on a bench under a ramp load. Health drawn around each actuator's nominal (FDJ and FSJ ±20 %,
η_O 0.68–0.98), sensor noise of tests/foreign's own kind. Each window goes through the public contract
with its actuator's document (no airframe: the aircraft check is skipped) and default pipeline sizes.

    python -m benchmarks.foreign_actuators [--blocks 5] [--seed 50000] [--docs]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS, RotaryActuator, actuator_from_dict, as_kind
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from tests.foreign.actuators import DRIVES, NOMINAL, document
from tests.foreign.windows import Ground, draw

RESULTS_MD = Path(__file__).resolve().parent.parent / "docs" / "results.md"
# Per block: what the hidden set holds of each actuator (6 in flight, 2 sweeps, 2 bench runs).
CONDITIONS = {"in flight": 6, "ground, no load": 2, "bench, ramp load": 2}


def where(condition: str, rng: np.random.Generator) -> Ground | None:
    """The flight (None: drawn by tests/foreign), or the ground: no load, or a ramp of a few hundred N·m/s."""
    if condition == "in flight":
        return None
    if condition == "ground, no load":
        return Ground()
    return Ground(load_nm=float(rng.uniform(-200.0, -50.0)), ramp_nmps=float(rng.uniform(200.0, 800.0)))


def run_one(name: str, condition: str, seed: int) -> dict[str, Any]:
    """One window's answer as errors against its truth, or its refusal."""
    rng = np.random.default_rng(seed)
    family = "thesis" if condition == "in flight" else "sweep"
    drawn = draw(seed, family, drive=DRIVES[name], nominal=NOMINAL[name], flight=where(condition, rng))
    actuator = THESIS if name == "thesis" else as_kind(actuator_from_dict(document(name)), RotaryActuator)
    try:
        result = estimate_window(window_from_dict(drawn.document), actuator=actuator)
    except InputError as exc:
        return {"refused": str(exc)}
    fdj, eta_o = result.estimates.FDJ, result.estimates.eta_O
    fdj_error = fdj.value - drawn.truth["FDJ"]
    row: dict[str, Any] = {
        "fdj_relative": fdj_error / drawn.truth["FDJ"],
        "fdj_z": fdj_error / fdj.std if fdj.std else float("nan"),
        "eta_read": eta_o is not None,
    }
    if eta_o is not None and eta_o.std:
        eta_error = eta_o.value - drawn.truth["eta_O"]
        row |= {"eta_error": eta_error, "eta_z": eta_error / eta_o.std}
    return row


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    answered = [r for r in rows if "refused" not in r]
    fdj = np.abs([r["fdj_relative"] for r in answered])
    eta = np.abs([r["eta_error"] for r in answered if "eta_error" in r])

    def cover(key: str) -> float:
        values = np.abs([r[key] for r in answered if key in r])
        return float(np.mean(values <= 2.0)) if len(values) else np.nan

    return {
        "n": len(rows),
        "answered": len(answered),
        "eta_read": sum(r["eta_read"] for r in answered),
        "fdj_mean": float(fdj.mean()) if len(fdj) else np.nan,
        "fdj_worst": float(fdj.max()) if len(fdj) else np.nan,
        "eta_mean": float(eta.mean()) if len(eta) else np.nan,
        "eta_worst": float(eta.max()) if len(eta) else np.nan,
        "fdj_cover": cover("fdj_z"),
        "eta_cover": cover("eta_z"),
        "refusals": [r["refused"] for r in rows if "refused" in r][:3],
    }


def markdown(table: dict[tuple[str, str], dict[str, Any]], blocks: int, seconds: float) -> str:
    lines = [
        f"{blocks} blocks of {sum(CONDITIONS.values())} windows per actuator ({', '.join(f'{n} {c}' for c, n in CONDITIONS.items())}),",  # noqa: E501
        "0.5 s at 10 kHz, drawn by `tests/foreign` with each actuator's own constants (`tests/foreign/actuators.py`:",
        "*heavier*: gear ratio 320, k_T 0.12 N·m/A, J_M 6e-5 kg·m², G_P 6e4, GAP 0.08, backlash 4 mrad, stops ±25°;",
        "*smaller*: 800, 0.05 N·m/A, 1.2e-5 kg·m², 1.5e5, 0.03, 6 mrad, ±30°; and the thesis's), each read with its",
        "own `ema-actuator/1` document (no airframe). In flight: thesis-family commands; on the ground: a pre-flight",
        "sweep without load (η_O cannot show: the answer gives none, with the reason), or a bench sweep under a",
        f"ramp load. Errors: FDJ relative, η_O absolute (windows with a load). Total {seconds:.0f} s.",
        "",
        "| actuator | condition | answered | η_O read | FDJ mean / worst error | η_O mean / worst error | ±2 std coverage FDJ / η_O |",  # noqa: E501
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for (name, condition), s in table.items():
        eta = "—" if np.isnan(s["eta_mean"]) else f"{s['eta_mean']:.4f} / {s['eta_worst']:.4f}"
        eta_cover = "—" if np.isnan(s["eta_cover"]) else f"{100 * s['eta_cover']:.0f} %"
        fdj = f"{100 * s['fdj_mean']:.2f} % / {100 * s['fdj_worst']:.2f} %"
        lines.append(
            f"| {name} | {condition} | {s['answered']}/{s['n']} | {s['eta_read']} | {fdj} | {eta} | "
            f"{100 * s['fdj_cover']:.0f} % / {eta_cover} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=5)
    parser.add_argument("--seed", type=int, default=50_000)
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    started, table = time.perf_counter(), {}
    for a, name in enumerate(("heavier", "smaller", "thesis")):
        for c, (condition, count) in enumerate(CONDITIONS.items()):
            seeds = [args.seed + 10_000 * a + 1_000 * c + k for k in range(args.blocks * count)]
            table[(name, condition)] = summary([run_one(name, condition, seed) for seed in seeds])
            print(name, condition, table[(name, condition)], flush=True)
    text = markdown(table, args.blocks, time.perf_counter() - started)
    print(text)
    if args.docs:
        command = f"python -m benchmarks.foreign_actuators --blocks {args.blocks} --seed {args.seed} --docs"
        write_section("Actuators unlike the thesis's, in flight and on the ground", command, text, RESULTS_MD)


if __name__ == "__main__":
    main()
