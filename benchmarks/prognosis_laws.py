"""The remaining life on wear of laws the code does not have: docs/prognosis.md.

Histories drawn by ``tests/prognosis/histories.py`` (laws only the tests implement: a line, a doubling
every eighth of the time to the threshold, a cube with a slow line, a smooth onset, a sinh, a crack's
hyperbolic growth, and steady), FDJ from 0.05 to the threshold 0.075 N·m, crossing 20–60 h after the
last window. For each law and each kind of history (windows, their std): how often the 90 % interval
holds the true remaining life, the median error of the median, how often it is within 35 %, and the
false alarms of the steady ones.

    python -m benchmarks.prognosis_laws [--per-law 40] [--docs]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ema.cli.benchmark_docs import write_section
from ema.prognosis.outlook import outlook
from ema.prognosis.trend import Series
from tests.prognosis.histories import LAWS, THRESHOLD, history

PROGNOSIS_MD = Path(__file__).resolve().parent.parent / "docs" / "prognosis.md"
KINDS = {
    "20 windows, std 0.3 mN·m": (20, 3e-4),
    "20 windows, std 1 mN·m": (20, 1e-3),
    "60 windows, std 0.3 mN·m": (60, 3e-4),
    "10 windows, std 0.3 mN·m": (10, 3e-4),
}


def score(law: str, n: int, std: float, histories: int) -> dict[str, float]:
    held = close = alarms = 0
    errors = []
    for seed in range(histories):
        h = history(law, 9000 + seed, n=n, std=std)
        series = Series("FDJ", h.hours, h.values, h.stds, [str(i) for i in range(n)])
        life = outlook(series, threshold=THRESHOLD, direction="above").life
        if law == "steady":
            alarms += life.status == "crossing predicted"
            continue
        held += life.status == "crossing predicted" and (life.rul_low or 0.0) <= h.true_life <= (
            life.rul_high or np.inf
        )
        if life.rul is not None:
            errors.append(abs(life.rul / h.true_life - 1.0))
            close += errors[-1] <= 0.35
    median = float(np.median(errors)) if errors else np.nan
    return {"held": held, "close": close, "alarms": alarms, "median_error": median}


def markdown(rows: dict[tuple[str, str], dict[str, float]], histories: int, seconds: float) -> str:
    lines = [
        f"{histories} histories per law and kind, drawn by `tests/prognosis/histories.py` with laws none of which is a",
        "law of `prognosis/laws.py` (the code's exponential is e^(k·s), the tests' doubling 2^(t/T); its power law",
        "starts at the first window, the tests' cube carries a line beside; its knee is a softened broken line, the",
        "tests' onset a softplus of another width; the crack's hyperbolic growth and the sinh have no counterpart).",
        "Held: the 90 % interval holds the true life; within 35 %: the median; steady: claims of a crossing.",
        f"Total {seconds:.0f} s.",
        "",
        "| law | " + " | ".join(KINDS) + " |",
        "|---|" + "---:|" * len(KINDS),
    ]
    for law in LAWS:
        cells = []
        for kind in KINDS:
            r = rows[(law, kind)]
            if law == "steady":
                cells.append(f"{r['alarms']} alarms")
            else:
                median = f"median error {100 * r['median_error']:.0f} %"
                cells.append(f"held {r['held']}, within 35 % {r['close']} ({median})")
        lines.append(f"| {law} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-law", type=int, default=40)
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/prognosis.md")
    args = parser.parse_args()
    started = time.perf_counter()
    rows = {(law, kind): score(law, n, std, args.per_law) for law in LAWS for kind, (n, std) in KINDS.items()}
    text = markdown(rows, args.per_law, time.perf_counter() - started)
    print(text)
    if args.docs:
        command = f"python -m benchmarks.prognosis_laws --per-law {args.per_law} --docs"
        write_section("Wear of laws the code does not have", command, text, PROGNOSIS_MD)


if __name__ == "__main__":
    main()
