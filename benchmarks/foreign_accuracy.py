"""Accuracy and honesty of ``ema estimate`` on windows our own code did not draw: docs/results.md.

Every window comes from ``tests.foreign`` (an independent implementation of the model, with its
own command families, sensor noise and quantization) and goes through the public contract
(``ema-window/1`` document -> ``estimate_window``). For each group of windows: how many were
answered, the mean and worst |error| (relative, and in % of the thesis's range: 0.02 N·m for FDJ,
0.30 for η_O), the coverage: the share of answers whose ±2 std holds the truth (FSJ: of the
answers that gave one), and how many errors pass 10 % of the range (and of those, how many the
answer itself said were weakly determined).

    python -m benchmarks.foreign_accuracy [--per-group 60] [--seed 7000] [--docs]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.accuracy_by_wear import wear_figure, wear_table
from benchmarks.foreign_groups import group_seed, groups
from benchmarks.tails import BOUND, FIRST_NOISE_SEED, expected_over
from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.estimate.documents.window_facts import HistoryReadings
from ema.estimate.report import WEAK_SHARE_OF_RANGE, share_of_range
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.window import window_from_dict
from tests.foreign.windows import Draw

RESULTS_MD = Path(__file__).resolve().parent.parent / "docs" / "results.md"


def run_one(window: Draw, history: HistoryReadings | None = None) -> dict[str, Any]:
    """The answer for one window (with what other windows of its actuator read, if given), as errors and
    z-scores against its truth (or the refusal)."""
    try:
        result = estimate_window(window_from_dict(window.document), history=history, actuator=THESIS)
    except InputError as exc:
        return {"refused": str(exc)}
    row: dict[str, Any] = {"seconds": result.timings_s.total}
    estimates = result.estimates.model_dump()
    for name in ("FDJ", "eta_O", "FSJ"):
        entry = estimates[name]
        if entry is None or entry["std"] is None:
            continue
        error = entry["value"] - window.truth[name]
        row[name] = {
            "relative": error / window.truth[name],
            "z": error / entry["std"],
            "truth": window.truth[name],
            "value": entry["value"],
            "std": entry["std"],
        }
        if name in ("FDJ", "eta_O"):
            row[name]["of_range"] = share_of_range(name, error, ranges=THESIS.ranges)
            row[name]["weak"] = entry["weakly_determined"]
    return row


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    answered = [r for r in rows if "refused" not in r]
    out: dict[str, Any] = {"n": len(rows), "answered": len(answered)}
    for name in ("FDJ", "eta_O", "FSJ"):
        found = [r[name] for r in answered if name in r]
        if not found:
            continue
        relative = np.abs([f["relative"] for f in found])
        out[name] = {
            "n": len(found),
            "mean_rel_pct": 100 * float(relative.mean()),
            "max_rel_pct": 100 * float(relative.max()),
            "coverage": float(np.mean(np.abs([f["z"] for f in found]) <= 2.0)),
        }
        if name in ("FDJ", "eta_O"):
            of_range = np.abs([f["of_range"] for f in found])
            over = of_range > BOUND
            weak = np.array([f["weak"] for f in found])
            stds = np.array([share_of_range(name, f["std"], ranges=THESIS.ranges) for f in found])
            out[name].update(
                expected=expected_over(stds),
                expected_not_weak=expected_over(stds[~weak]),
                mean_range_pct=100 * float(of_range.mean()),
                max_range_pct=100 * float(of_range.max()),
                over=int(over.sum()),
                over_weak=int((over & weak).sum()),
            )
    return out


def _errors(s: dict[str, Any]) -> str:
    """mean / worst relative error, and the same in % of the thesis's range."""
    relative = f"{s['mean_rel_pct']:.2f} % / {s['max_rel_pct']:.2f} %"
    return f"{relative} ({s['mean_range_pct']:.1f} / {s['max_range_pct']:.1f} % of range)"


def _expected(s: dict[str, Any]) -> str:
    return f"{s['expected']:.1f} ({s['expected_not_weak']:.1f})"


def table(summaries: dict[str, dict[str, Any]]) -> str:
    header = "| windows | answered | FDJ mean / worst error | η_O mean / worst error | ±2 std coverage FDJ / η_O "
    lines = [
        header + f"| over {100 * BOUND:.0f} % of range FDJ / η_O (said weak) "
        "| expected from the stds FDJ / η_O (not weak) | FSJ given: coverage |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, s in summaries.items():
        if "FDJ" not in s:
            lines.append(f"| {name} | {s['answered']}/{s['n']} (refused: too little motion) | — | — | — | — | — | — |")
            continue
        f, e = s["FDJ"], s["eta_O"]
        fsj = f"{s['FSJ']['n']}: {100 * s['FSJ']['coverage']:.0f} %" if "FSJ" in s else "0: —"
        lines.append(
            f"| {name} | {s['answered']}/{s['n']} | {_errors(f)} | {_errors(e)} "
            f"| {100 * f['coverage']:.0f} % / {100 * e['coverage']:.0f} % "
            f"| {f['over']} ({f['over_weak']}) / {e['over']} ({e['over_weak']}) "
            f"| {_expected(f)} / {_expected(e)} | {fsj} |"
        )
    return "\n".join(lines)


def confidently_past(answer: dict[str, Any]) -> bool:
    """Past ``BOUND`` and not said weak: the answers the issue's bound is about."""
    return abs(answer["of_range"]) > BOUND and not answer["weak"]


def redrawn_tails(rows: dict[str, list[dict[str, Any]]], seed: int, count: int) -> list[dict[str, Any]]:
    """Every answer past ``BOUND`` not said weak, with its z as logged and over ``count`` answers to the
    same window with fresh realizations of its sensor noise (``benchmarks.tails``)."""
    makers, found = groups(), []
    for name, answers in rows.items():
        for i, row in enumerate(answers):
            tails = [p for p in ("FDJ", "eta_O") if p in row and confidently_past(row[p])]
            if not tails:
                continue
            make, window_seed = makers[name], group_seed(name, i, seed)
            again = [run_one(make(window_seed, noise_seed=FIRST_NOISE_SEED + k)) for k in range(count)]
            for p in tails:
                z = np.array([a[p]["z"] for a in again if p in a])
                found.append({"window": f"{name} #{i}", "parameter": p, "z": row[p]["z"], "redrawn": z})
    return found


def tails_table(found: list[dict[str, Any]], count: int) -> str:
    lines = [
        f"| window | parameter | z as logged | {count} fresh draws of its noise: RMS z / worst abs(z) |",
        "|---|---|---:|---:|",
    ]
    for f in found:
        z = f["redrawn"]
        lines.append(
            f"| {f['window']} | {f['parameter'].replace('eta_O', 'η_O')} | {f['z']:+.1f} "
            f"| {np.sqrt(np.mean(z**2)):.2f} / {np.abs(z).max():.2f} |"
        )
    return "\n".join(lines)


def pooled(rows: dict[str, list[dict[str, Any]]], worn_only: bool) -> dict:
    chosen = [r for name, rs in rows.items() for r in rs if name.startswith("worn") == worn_only and "held" not in name]
    return summarize(chosen)


# What each group of the accuracy table holds, for the docs section.
GROUPS_TEXT = "\n".join(
    [
        "windows per group (3 held positions), drawn by `tests/foreign` (an independent",
        "implementation of the model: exact RL step, RK4 aircraft from the instantaneous deflection, trim at",
        "true airspeed, 100 kHz command table, its own sensor noise and quantization), health uniform in",
        "Table 3.1's ranges (worn: FDJ 1.3–2.5x nominal, η_O 0.45–0.66), random flight condition; default",
        "pipeline sizes. *Drive unlike the document's*: the five families, with a loop that departs from the",
        "document's and from every simulation the pipeline runs, unlogged (bus ±10 %, position gain ±2 %, up",
        "to 50 µs of lag, a speed read with up to 0.5 rad/s of noise: `unlike_the_spec`). *Sensors behind",
        "filters*: the five families, each sensor's signal and noise through a causal moving average, as a",
        "real filter passes them (current 2–6 samples, speed and position 2–8, the hinge moment 10–40:",
        "`through_filters`, `filter_widths`): logged up to 2 ms late, the noise's low frequencies carrying",
        "up to 40x the power of white noise of the same std. *Noise behind filters, not the signal*: the",
        "same filters on the noise alone (`draw(filter_samples=...)`), as an amplifier's own noise behind its",
        "output filter would be: the noise reads as a filter's delay either way, and the product weighs the two",
        "readings by the lag the deflection shows in the aircraft's band and by the equation error",
        "(`ema.kinds.rotary.prepare.alignment`), its stds carrying both where neither decides.",
        "*Sensor glitches*: the five families with",
        "1–5 spikes of 50–500 noise stds on each sensor, one in four two samples long (`with_spikes`).",
        "*Sensors off zero*: the five families with the hinge moment 1–10 N·m or the current 0.04–0.25 A",
        "off zero, in turn (`off_zero`), read and taken off per window "
        "(`ema.kinds.rotary.prepare.departures.zero_offset`).",
        "*Viscous friction 1.2–2x the document's*: the five families with C above the document's, as a cold grease",
        "has it (`viscous`), read per window and used by every estimator",
        "(`ema.kinds.rotary.prepare.departures.viscosity`). The",
        "*worn* groups with these two: a worn transmission's k = 1/η_O − 1 reaches 1.2, and so does the",
        "share of a hinge offset that passes for FDJ where the window cannot tell which sensor is off.",
        "*k_T, current gain or J_M off*: the five families with, in turn, k_T 0.95–1.05x the document's (magnets",
        "warm or cold), the current sensor's gain 0.97–1.03 and J_M 0.9–1.1x (`drive_off`), read per window",
        "and corrected (`ema.kinds.rotary.prepare.departures.drive_constants`); and on worn actuators. *Hinge moment",
        "gain*: the five",
        "families with the hinge moment logged 0.95–1.05x the true one (`with_hinge_gain`), read per window",
        "from Eq. 5.1's aiding and opposing load terms with Eq. 3.4 and corrected",
        "(`ema.kinds.rotary.prepare.departures.hinge_gain`).",
        "*Longest window*: the five families over 10 s, the longest the issue names, processed at 5 kHz (the",
        "pipeline averages a long log down, not below 5 kHz up to 10 s: `ema.kinds.rotary.prepare.conditioning`).",
    ]
)


def report(rows: dict[str, list[dict[str, Any]]], per_group: int, seconds: float, tails: str) -> str:
    """The docs section: the tables (``tails``: ``tails_table``'s) and what to read in them."""
    summaries = {name: summarize(r) for name, r in rows.items()}
    summaries["all flight windows (not worn)"] = pooled(rows, worn_only=False)
    summaries["all worn windows"] = pooled(rows, worn_only=True)
    return "\n".join(
        [
            f"{per_group} {GROUPS_TEXT}",
            f"Total {seconds:.0f} s.",
            "",
            table(summaries),
            "",
            f"*Over {100 * BOUND:.0f} % of range*: answers whose error passes that share of the thesis's range, and in",
            "brackets how many of them said so themselves: their ±2 std spans more than "
            f"{100 * WEAK_SHARE_OF_RANGE:.0f} %"
            " of the range and",
            "a note calls the parameter weakly determined by the window. A 0.1 s window, a 1–2 kHz log or a",
            "hinge moment of a few N·m (the load term then a few tenths of a mN·m) holds little of η_O, and",
            "extrapolating the friction line to zero load from a high, steady load holds little of FDJ.",
            "*Expected from the stds*: how many errors past 10 % of the range the answers' own stds promise",
            "(Σ erfc(10 % / (std·√2)) over the group's answers, in brackets over those not said weak:",
            "`benchmarks.tails`); more observed than expected would mean stds too narrow in the tails.",
            "How many such errors the sensor noise alone makes unavoidable: `benchmarks.information_limit`",
            "(next section).",
            "",
            "The answers past 10 % of range not said weak, each answered again with fresh realizations of its",
            "window's sensor noise (the same motion, noise levels and filters: `draw(noise_seed=...)`): a tail",
            "of the noise reads |z| about 1 again, a bias the window carries keeps its z.",
            "",
            tails,
            "",
            "Against wear (every answered window, grouped by its true FDJ over the nominal 0.05 N·m; the worn",
            "windows reach η_O 0.45, Case 1C's irreversible range, where η_A < 0):",
            "",
            wear_table(rows),
            "",
            "![estimate against truth over the wear range](figures/wear_parity.png)",
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-group", type=int, default=60, help="windows per group (held positions: 3)")
    parser.add_argument(
        "--seed", type=int, default=7000, help="first seed (the benchmark's windows are not the tests')"
    )
    parser.add_argument("--tail-draws", type=int, default=8, help="noise redraws per answer past 10 %% not weak")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    started = time.perf_counter()
    rows: dict[str, list[dict[str, Any]]] = {}
    for name, make in groups().items():
        count = 3 if "held" in name else args.per_group
        rows[name] = [run_one(make(group_seed(name, i, args.seed))) for i in range(count)]
        print(f"{name}: {summarize(rows[name])}", flush=True)
    tails = tails_table(redrawn_tails(rows, args.seed, args.tail_draws), args.tail_draws)
    body = report(rows, args.per_group, time.perf_counter() - started, tails)
    print(body)
    if args.docs:
        wear_figure(rows, RESULTS_MD.parent / "figures" / "wear_parity.png")
        write_section(
            "Accuracy on windows our code did not draw",
            "python -m benchmarks.foreign_accuracy --docs",
            body,
            RESULTS_MD,
        )


if __name__ == "__main__":
    main()
