"""How often a clean window draws ``model_misfit``: the test's false-alarm rate on windows we did not draw.

Clean ``tests.foreign`` windows (no effect the model lacks), the five command families in turn, each
through the public contract. The note must appear at the stated rate (``MISFIT_FALSE_ALARM``) or less;
the table gives the rate, the ratios and the limits, and whether the check line and the note agreed.

    python -m benchmarks.misfit_rate [--windows 100] [--seed 5000] [--docs]
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from ema.cli.benchmark_docs import write_section
from ema.cli.printing import check_line
from ema.estimate import thread_budget
from ema.estimate.assess.weighing import MISFIT_FALSE_ALARM
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.window import window_from_dict
from tests.foreign.windows import draw

RESULTS_MD = Path(__file__).resolve().parent.parent / "docs" / "results.md"
FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")


def measure(windows: int, seed: int) -> dict[str, Any]:
    ratios, limits, flagged, contradictions = [], [], 0, 0
    for i in range(windows):
        drawn = draw(seed + i, FAMILIES[i % len(FAMILIES)])
        result = estimate_window(window_from_dict(drawn.document), actuator=THESIS)
        check = result.check
        said = any(note.code == "model_misfit" for note in result.notes)
        flagged += said
        ratios.append(check.equation_error_ratio)
        limits.append(check.equation_error_limit)
        line = check_line(check)
        contradictions += said and "lacks" not in line
        print(f"{drawn.document['window_id']}: ratio {ratios[-1]:.3f}, limit {limits[-1]:.3f}, note {said}", flush=True)
    return {
        "n": windows,
        "flagged": flagged,
        "ratios": np.array(ratios),
        "limits": np.array(limits),
        "contradictions": contradictions,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=100)
    parser.add_argument("--seed", type=int, default=5000)
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    found = measure(args.windows, args.seed)
    ratios, limits = found["ratios"], found["limits"]
    assert isinstance(ratios, np.ndarray) and isinstance(limits, np.ndarray)
    q = np.quantile
    body = (
        f"{found['n']} clean `tests.foreign` windows (0.5 s at 10 kHz, the five command families in turn, seeds "
        f"{args.seed}–{args.seed + args.windows - 1}), each through `ema-window/1`. The note `model_misfit` is "
        f"said past the limit a window the model explains exceeds {100 * MISFIT_FALSE_ALARM:g} % of the time "
        f"(`ema.estimate.assess.weighing.misfit_limit`).\n\n"
        f"| windows | note said | equation-error ratio (median, 90 %, max) | limit (median, min–max) | "
        f"check line and note disagree |\n|---|---|---|---|---|\n"
        f"| {found['n']} | {found['flagged']} ({100 * found['flagged'] / found['n']:.0f} %) | "
        f"{q(ratios, 0.5):.3f}, {q(ratios, 0.9):.3f}, {ratios.max():.3f} | "
        f"{q(limits, 0.5):.3f}, {limits.min():.3f}–{limits.max():.3f} | {found['contradictions']} |\n"
    )
    print(body)
    if args.docs:
        write_section(
            "The misfit note on clean windows",
            f"python -m benchmarks.misfit_rate --windows {args.windows} --seed {args.seed} --docs",
            body,
            RESULTS_MD,
        )


if __name__ == "__main__":
    main()
