"""How many simulations the answer needs: accuracy, honesty and time against the simulation budget.

The same windows from ``tests.foreign`` (the independent implementation) are answered with each
budget (training simulations + held-out ones), one budget after another in one run, so the times
compare as ratios. Per budget: mean |error| in % of the thesis's range, ±2 std coverage, answers
past 10 % of range not said weak, and the pipeline's p50 / p95 seconds.

    python -m benchmarks.simulation_budget [--per-group 8] [--budgets 64+24,48+16,32+16] [--docs]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.foreign_groups import group_seed, groups
from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.estimate.config import PipelineConfig
from ema.estimate.report import share_of_range
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.window import window_from_dict

RESULTS_MD = Path(__file__).resolve().parent.parent / "docs" / "results.md"
GROUPS = (
    "thesis",
    "cruise",
    "gust",
    "doublet",
    "steps",
    "short window (0.1 s, gust)",
    "low log rate (1-2 kHz)",
    "worn, gust",
    "sensors behind filters",
    "k_T, current gain or J_M off",
)
BOUND = 0.10  # of the range: an error past it, not said weak, is confidently wrong


def scored(config: PipelineConfig, windows: list[Any]) -> dict[str, Any]:
    """Errors, coverage, confidently wrong answers and seconds of ``config`` over ``windows``."""
    errors: dict[str, list[float]] = {"FDJ": [], "eta_O": []}
    inside: dict[str, list[bool]] = {"FDJ": [], "eta_O": []}
    wrong, seconds = 0, []
    for draw in windows:
        try:
            result = estimate_window(window_from_dict(draw.document), config, actuator=THESIS)
        except InputError:
            continue
        seconds.append(result.timings_s.total)
        for name in errors:
            entry = getattr(result.estimates, name)
            if entry is None or entry.std is None:
                continue
            of_range = abs(share_of_range(name, entry.value - draw.truth[name], ranges=THESIS.ranges))
            errors[name].append(of_range)
            inside[name].append(abs(entry.value - draw.truth[name]) <= 2 * entry.std)
            wrong += int(of_range > BOUND and not entry.weakly_determined)
    return {
        "error": {name: 100 * float(np.mean(v)) for name, v in errors.items()},
        "coverage": {name: 100 * float(np.mean(v)) for name, v in inside.items()},
        "wrong": wrong,
        "answered": len(seconds),
        "p50": float(np.median(seconds)),
        "p95": float(np.quantile(seconds, 0.95)),
    }


def table(results: dict[str, dict[str, Any]], n: int) -> str:
    rows = [
        "| simulations (train + held out) | answered | error FDJ / η_O (% of range) | ±2 std coverage FDJ / η_O "
        "| past 10 %, not said weak | p50 / p95 [s] | time vs the default |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    reference = next(iter(results.values()))["p50"]
    for budget, r in results.items():
        rows.append(
            f"| {budget} | {r['answered']}/{n} | {r['error']['FDJ']:.2f} % / {r['error']['eta_O']:.2f} % "
            f"| {r['coverage']['FDJ']:.0f} % / {r['coverage']['eta_O']:.0f} % | {r['wrong']} "
            f"| {r['p50']:.3f} / {r['p95']:.3f} | {r['p50'] / reference:.2f}x |"
        )
    return "\n".join(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-group", type=int, default=8)
    parser.add_argument("--budgets", default="64+24,48+16,32+16,24+12")
    parser.add_argument("--seed", type=int, default=90_000)
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    makers = groups()
    windows = [makers[g](group_seed(g, i, args.seed)) for g in GROUPS for i in range(args.per_group)]
    started = time.perf_counter()
    estimate_window(window_from_dict(windows[0].document), actuator=THESIS)  # JIT and caches outside the timing
    results = {}
    for budget in args.budgets.split(","):
        train, held = (int(part) for part in budget.split("+"))
        config = PipelineConfig(n_simulations=train, check_simulations=held)
        results[budget] = scored(config, windows)
        print(budget, results[budget], flush=True)
    body = "\n".join(
        [
            f"{len(windows)} windows from `tests/foreign` ({args.per_group} per group: {', '.join(GROUPS)}), each",
            "answered with every budget in one run, one budget after another; the times compare as ratios.",
            f"Total {time.perf_counter() - started:.0f} s.",
            "",
            table(results, len(windows)),
        ]
    )
    print(body)
    if args.docs:
        command = f"python -m benchmarks.simulation_budget --per-group {args.per_group} --budgets {args.budgets} --docs"
        write_section("How many simulations the answer needs", command, body, path=RESULTS_MD)


if __name__ == "__main__":
    main()
