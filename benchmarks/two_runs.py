"""Two runs of one machine, where the model misses part of it: do their FDJ agree within their stds?

On the independent closed-form servo (``tests/foreign/servo.py``), a load whose viscous friction differs with the
direction of motion (160 / 240 N·s/m) read with the document's symmetric model: each seed logged twice, once as its
controller moves it and once with a command of its own added (a different excitation, another seed's set point),
FDJ against the truth (20 N) and the two runs against 2 std of their difference; the same loads with a symmetric
friction as the control (the model misses nothing). Then the EMPS estimation run, whole, in halves and in quarters,
with the bundled document and with the one ``ema calibrate`` completes from it.

    python -m benchmarks.two_runs [--seeds 6] [--docs]
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np

from benchmarks.emps import calibrations, estimation_run
from benchmarks.foreign_accuracy import RESULTS_MD
from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.estimate.documents import Estimate
from ema.kinds import estimate
from ema.model.actuator import ActuatorDocument, actuator_from_dict
from ema.model.window import Window, window_from_dict
from tests.foreign import servo as foreign

TITLE = "Two runs of one machine, where the model misses part of it"
ASYMMETRIC = foreign.Load(viscous_up_ns_per_m=160.0, viscous_down_ns_per_m=240.0)
READING = """Reading it. Where the model misses part of a log (`model_misfit`: its Eq. 5.1 residual beyond what its
simulations reach), the estimate reads each load effect the log holds evidence for (its constants physical, every
held-out fifth predicted better, the held-out residual cut by 5 % at least) and widens every constant's std, in
quadrature, by half of what the farthest such reading moves it (`model_form`): which effect is missing one log
cannot tell, and the runs of one machine excite it differently, so a std of the noise alone claims what a second
run does not confirm. The control's logs hold no such evidence and keep their stds. A part of a log may hold
evidence for fewer effects than the whole (each held-out fifth is shorter): there its std is the noise's."""


def _fdj(result: Estimate) -> tuple[float, float, bool]:
    f = result.estimates.FDJ
    assert f.std is not None, "a servo's FDJ carries its std"
    return f.value, f.std, any(n.code == "model_form" for n in result.notes)


def foreign_rows(seeds: int) -> tuple[list[str], dict[str, tuple[int, int, int]]]:
    """The table's rows, and per load: (pairs within 2 std, readings holding the truth within 2 std, readings)."""
    document = actuator_from_dict(foreign.DOCUMENT)
    rows, counts = [], {}
    for label, load in (("160 / 240 N·s/m (missed)", ASYMMETRIC), ("200 / 200 N·s/m (control)", foreign.Load())):
        pairs = held = 0
        for seed in range(seeds):
            plain = _fdj(estimate(window_from_dict(foreign.draw(seed, load)), actuator=document))
            excited = _fdj(estimate(window_from_dict(foreign.draw(seed + 10, load, excited=True)), actuator=document))
            z = (plain[0] - excited[0]) / float(np.hypot(plain[1], excited[1]))
            truth = [(run[0] - load.fdj_n) / run[1] for run in (plain, excited)]
            pairs += abs(z) <= 2.0
            held += sum(abs(t) <= 2.0 for t in truth)
            widened = "/".join("yes" if run[2] else "no" for run in (plain, excited))
            rows.append(
                f"| {label} | {seed} | {plain[0]:.3f} ± {plain[1]:.3f} | {excited[0]:.3f} ± {excited[1]:.3f} | "
                f"{z:+.2f} | {truth[0]:+.2f} / {truth[1]:+.2f} | {widened} |"
            )
        counts[label] = (pairs, held, 2 * seeds)
    return rows, counts


def parts(window: Window) -> list[tuple[str, Window]]:
    """The log whole, its halves and its quarters, each named."""
    n = window.n_samples
    spans = [("whole", 0, n), ("first half", 0, n // 2), ("second half", n // 2, n)]
    spans += [(f"quarter {i + 1}", i * n // 4, (i + 1) * n // 4) for i in range(4)]
    return [
        (name, replace(window, signals={k: v[a:b] for k, v in window.signals.items()}, window_id=name))
        for name, a, b in spans
    ]


def emps_rows(window: Window, documents: dict[str, ActuatorDocument]) -> list[str]:
    rows = []
    for label, document in documents.items():
        for name, part in parts(window):
            value, std, widened = _fdj(estimate(part, actuator=document))
            rows.append(f"| {label} | {name} | {value:.3f} ± {std:.3f} | {'yes' if widened else 'no'} |")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=6)
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure(None)
    rows, counts = foreign_rows(args.seeds)
    window = estimation_run()
    documents = dict(zip(("bundled", "calibrated"), calibrations(window, 1), strict=True))
    said = "; ".join(
        f"{label}: {pairs} of {total // 2} pairs within 2 std of their difference, {held} of {total} readings hold "
        "the truth within 2 std"
        for label, (pairs, held, total) in counts.items()
    )
    body = "\n".join(
        [
            "| load | seed | as its controller moves it | a command of its own added | z of the difference | "
            "truth, in stds | stds widened |",
            "|---|---:|---:|---:|---:|---:|---|",
            *rows,
            "",
            f"{said}.",
            "",
            READING,
            "",
            "| EMPS document | part of the estimation run | FDJ [N] | stds widened |",
            "|---|---|---:|---|",
            *emps_rows(window, documents),
        ]
    )
    print(body)
    if args.docs:
        write_section(TITLE, typed_command(), body, RESULTS_MD)


if __name__ == "__main__":
    main()
