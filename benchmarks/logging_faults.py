"""What ``ema estimate`` makes of a window whose logger wrote a sensor's last value after it stopped
updating, or filled a gap with zeros (``tests.foreign.faults``), on windows of every group of
``benchmarks.foreign_accuracy`` in turn (docs/results.md, "Logging faults").

    python -m benchmarks.logging_faults [--per-fault 52] [--docs]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from typing import Any

from benchmarks.foreign_accuracy import RESULTS_MD, run_one, summarize, table
from benchmarks.foreign_groups import group_seed, groups
from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.kinds.rotary.prepare.stale import stale_runs
from ema.model.actuator import THESIS
from ema.model.window import RotaryWindow, as_window, window_from_dict
from tests.foreign.faults import FAULTS, with_fault

FIRST_SEED = 1_000_000  # apart from every other benchmark's (foreign_history's reach ~610 000) and the tests'
CLEAN = "none: the windows as drawn"


def report(rows: dict[str, list[dict[str, Any]]], found: dict[str, int], per_fault: int, seconds: float) -> str:
    summaries = {}
    for name, answers in rows.items():
        label = name if name == CLEAN else f"{name} (found in {found[name]})"
        summaries[label] = summarize(answers)
    return "\n".join(
        [
            f"{per_fault} windows of `tests/foreign`, one of each group of the accuracy table in turn (0.1–10 s,",
            "1–100 kHz, worn, filtered, off zero, drives unlike the document's), each logged once more with one fault",
            "(`tests/foreign/faults.py`): a sensor whose logger kept writing its last value after it stopped",
            "updating, or a gap filled with zeros, over 5–25 % of the window somewhere in it, or for 0.5–2 ms",
            "where the motor slews past 300 rad/s. *Found in*: windows where `ema.kinds.rotary.prepare.stale` takes a "
            "run "
            "of that",
            "sensor for one (a sensor quantized coarser than its noise, or a speed or position at rest, is left",
            "alone; a current at 0 a few noise stds from its flanks matters little). A run of up to 2 ms is",
            "bridged by the line between its flanks, a longer one cuts the window to the stretch with the most",
            "sliding motion (`window.read_span`). Columns as in the accuracy table above; the first row is the",
            "same windows as drawn. A long gap costs what the window loses with it: the stretch read is a shorter",
            "window, and one sliding one way cannot tell a sensor off zero or a cold grease from friction (drawn",
            "from other seeds, a worn doublet's gap left two such pieces: the one read was 8 ranges off, said weak,",
            "the other read 1.5 %).",
            "At 1 kHz a 0.5 ms dropout is 2 samples: neither a run (4 samples) nor a glitch (1 sample at that rate,",
            "where a current pulse at a reversal lasts 2–3), and it is read as logged.",
            f"Total {seconds:.0f} s.",
            "",
            table(summaries),
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-fault", type=int, default=52, help="windows per fault (each group in turn)")
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure()
    started = time.perf_counter()
    names = [name for name in groups() if "held" not in name]
    rows: dict[str, list[dict[str, Any]]] = {CLEAN: [], **{fault: [] for fault in FAULTS}}
    found = dict.fromkeys(FAULTS, 0)
    for i in range(args.per_fault):
        name = names[i % len(names)]
        seed = group_seed(name, i, FIRST_SEED)
        drawn = groups()[name](seed)
        rows[CLEAN].append(run_one(drawn))
        for label, fault in FAULTS.items():
            logged = replace(drawn, document=with_fault(drawn.document, fault, seed))
            found[label] += any(
                run.signal == fault.signal
                for run in stale_runs(as_window(window_from_dict(logged.document), RotaryWindow), drive=THESIS.params)
            )
            rows[label].append(run_one(logged))
        print(i, name, flush=True)
    body = report(rows, found, args.per_fault, time.perf_counter() - started)
    print(body)
    if args.docs:
        write_section("Logging faults", typed_command(), body, RESULTS_MD)


if __name__ == "__main__":
    main()
