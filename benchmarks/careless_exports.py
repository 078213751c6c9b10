"""What ``ema estimate`` does with a careless export of a foreign window: a sign convention, a unit or a
sample rate the log got wrong (``tests.foreign.careless``), on windows of every group of
``benchmarks.foreign_accuracy`` in turn (docs/results.md, "Careless exports").

    python -m benchmarks.careless_exports [--per-slip 104] [--docs]
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from dataclasses import replace

from benchmarks.foreign_accuracy import RESULTS_MD, run_one
from benchmarks.foreign_groups import group_seed, groups
from benchmarks.tails import BOUND
from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from tests.foreign.careless import SLIPS, Slip, exported
from tests.foreign.windows import Draw

FIRST_SEED = 100_000  # apart from the accuracy benchmarks' and the tests'
CLEAN = "none: the windows as drawn"


def outcome(drawn: Draw, slip: Slip | None) -> str:
    """``named`` (refused, naming the slip's field), ``other: <field>``, or for an answer ``weak`` (a
    parameter past the bound said weak, or none past it) or ``confident`` (past it, not said weak)."""
    sent = drawn if slip is None else replace(drawn, document=exported(drawn.document, slip))
    row = run_one(sent)
    if "refused" in row:
        field = row["refused"].split(": ")[0]
        return "named" if slip is not None and field == slip.field else f"other: {field}"
    past = [row[p] for p in ("FDJ", "eta_O") if p in row and abs(row[p]["of_range"]) > BOUND]
    return "confident" if any(not p["weak"] for p in past) else "weak"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-slip", type=int, default=104, help="windows per slip (each group in turn)")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    started = time.perf_counter()
    names = [name for name in groups() if "held" not in name]
    counts: dict[str, Counter] = {CLEAN: Counter(), **{slip: Counter() for slip in SLIPS}}
    for i in range(args.per_slip):
        name = names[i % len(names)]
        drawn = groups()[name](group_seed(name, i, FIRST_SEED))
        counts[CLEAN][outcome(drawn, None)] += 1
        for slip, how in SLIPS.items():
            counts[slip][outcome(drawn, how)] += 1
        print(i, name, flush=True)
    body = report(counts, args.per_slip, time.perf_counter() - started)
    print(body)
    if args.docs:
        write_section("Careless exports", typed_command(), body, RESULTS_MD)


def report(counts: dict[str, Counter], per_slip: int, seconds: float) -> str:
    lines = [
        f"{per_slip} windows of `tests/foreign`, one of each group of the accuracy table in turn (0.1–2 s,",
        "1–100 kHz, worn, filtered, off zero, drives unlike the document's), each exported once more with one",
        "slip (`tests/foreign/careless.py`) and sent as it is. *Refused, naming it*: the error names the",
        "field the slip is in (`ema/kinds/rotary/prepare/verdict.py`); *answered*: the estimate, scored against the",
        f"truth: within the bound if no parameter is past {100 * BOUND:.0f} % of range, or said weak if each",
        "past it says so; *confidently wrong* if one past it does not. A hinge moment in lbf·ft (0.74x) is",
        "much what η_O 0.74x as high would read in Eq. 5.1; the part of it that follows the deflection is",
        "0.74x the aircraft model's at the window's flight condition",
        "(`ema.kinds.rotary.prepare.departures.aircraft_check`), which",
        "reads the gauge's gain, and a moment out of step by its lag, unless its deflection moves slowly. There",
        "Eq. 5.1 fits the moment read at its lag a few % better at most, too little to refuse the window; that",
        "story is weighed by the likelihood ratio and its gap goes into the stds",
        "(`ema.kinds.rotary.prepare.step_lag`): a 20 ms",
        "slip was answered FDJ 13 % of range off at 2.7 std before. At 5 ms the ratio often cannot tell it from",
        "the noise; the lag the deflection's band reads decides most of those (3 confidently wrong before it).",
        "A window too short to divide the aircraft's ratio out is read as logged and with it divided out first,",
        "the stds carrying the gap (`ema.kinds.rotary.prepare.departures.read`; 2 confidently wrong 0.1 s gusts "
        "before).",
        "A current a tenth reads as a motor 10x stronger and a rotor 0.1x as heavy, which no drive",
        "has (`ema.kinds.rotary.prepare.departures.drive_constants`); one 0.71x (RMS for amplitude) reads as a motor",
        "1.41x as strong, or as",
        "well as a rotor ~0.7x as heavy with other friction: the window cannot tell them apart, and the stds carry",
        "the gap between the two readings (7 answers were confidently wrong before). Where Eq. 5.1 then puts η_O",
        "at its search bound, η_O and FDJ are said weak (`ema.estimate.report`; a 0.1 s gust read η_O 0.999 ± 0.009,",
        "the truth 0.70, before).",
        f"Total {seconds:.0f} s.",
        "",
        "| export | refused, naming it | refused, naming another field | answered: within the bound or said weak "
        "| answered, confidently wrong |",
        "|---|---:|---:|---:|---:|",
    ]
    for slip, seen in counts.items():
        other = sum(n for key, n in seen.items() if key.startswith("other"))
        fields = ", ".join(sorted({key.split(": ")[1] for key in seen if key.startswith("other")}))
        named = "—" if slip == CLEAN else str(seen["named"])
        lines.append(
            f"| {slip} | {named} | {other}{f' ({fields})' if fields else ''} | {seen['weak']} | {seen['confident']} |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    main()
