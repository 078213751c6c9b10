"""The calibration loop on windows that run into the end stops: a current gain against an inertia.

Windows of ``tests.foreign``'s ``stops`` family (a command past ±30°, held a third of the window or more,
one way then the other, 1.5 s at 10 kHz, a low-q̄ flight the motor can hold the stop against) with the
foreign implementation's own effect forms: a current sensor reading 0.94, 1.06 and 1.10 of the true
current, an inertia at 0.8 and 1.2 of the document's, and none. Per case and seed: what was named (or
declared ambiguous), and the |FDJ| + |η_O| relative error before and after. The rule the loop must keep:
no calibration makes the estimates worse, and no sensor fault is named as a mechanical effect.

    python -m benchmarks.calibration_stops [--seeds 4] [--docs]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ema.calibration.truth import with_truth_errors
from ema.cli.benchmark_docs import write_section
from ema.estimate import thread_budget
from ema.kinds.rotary.calibration import Calibrator
from ema.model.actuator import THESIS
from ema.model.window import RotaryWindow, as_window, window_from_dict
from tests.foreign.physics import Effects, Flight
from tests.foreign.windows import draw

DOCS = Path(__file__).resolve().parent.parent / "docs"
LOW_Q = Flight(airspeed_mps=100.0, altitude_m=5000.0)
CASES = {
    "none": Effects(),
    "current gain 0.94": Effects(current_sensor_gain=0.94),
    "current gain 1.06": Effects(current_sensor_gain=1.06),
    "current gain 1.10": Effects(current_sensor_gain=1.10),
    "inertia 0.8": Effects(inertia_factor=0.8),
    "inertia 1.2": Effects(inertia_factor=1.2),
}
RIGHT = {"current gain": {"current_sensor_gain"}, "inertia": {"inertia"}, "none": set()}
MECHANICAL = {"backlash", "position_friction", "stribeck", "viscous", "cogging"}


def one(case: str, seed: int) -> dict[str, object]:
    drawn = draw(seed, "stops", effects=CASES[case], duration_s=1.5, flight=LOW_Q)
    calibrator = Calibrator(seed=seed, actuator=THESIS)
    calibrator.fit([as_window(window_from_dict(drawn.document), RotaryWindow)], drawn.truth)
    report = with_truth_errors(calibrator.report_, drawn.truth)  # as every kind's calibration reports it
    assert report.error_pct_before is not None and report.error_pct_after is not None
    before = (report.error_pct_before["FDJ"] + report.error_pct_before["eta_O"]) / 100
    after = (report.error_pct_after["FDJ"] + report.error_pct_after["eta_O"]) / 100
    named = set(report.selected_effects)
    ambiguous = set(report.ambiguity.effects) if report.ambiguity else set()
    right = RIGHT[case.rsplit(" ", 1)[0] if case != "none" else "none"]
    outcome = ", ".join(sorted(named)) or "nothing"
    if ambiguous:
        outcome += f"; ambiguous: {' / '.join(report.ambiguity.effects)}" if report.ambiguity else ""
    return {
        "case": case,
        "seed": seed,
        "outcome": outcome,
        "right": (named == right) or bool(right & ambiguous),
        "before": before,
        "after": after,
        "worse": after > before * 1.001 + 1e-4,
        "forced": bool(case.startswith("current") and named & MECHANICAL),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/calibration.md")
    args = parser.parse_args()
    thread_budget.configure()
    rows = []
    for case in CASES:
        for seed in range(args.seeds):
            row = one(case, seed)
            print(row, flush=True)
            rows.append(row)
    lines = ["| effect | seed | named | error before → after | worse |", "|---|---|---|---|---|"]
    lines += [
        f"| {r['case']} | {r['seed']} | {r['outcome']} | {r['before']:.3f} → {r['after']:.3f} | "
        f"{'yes' if r['worse'] else 'no'} |"
        for r in rows
    ]
    worse, forced = sum(bool(r["worse"]) for r in rows), sum(bool(r["forced"]) for r in rows)
    right = sum(bool(r["right"]) for r in rows)
    body = (
        f"{len(rows)} calibrations of one 1.5 s `stops` window each (seeds 0–{args.seeds - 1}); the error is "
        "|FDJ| + |η_O| relative to the truth. Named right (or declared ambiguous with the right one): "
        f"{right} of {len(rows)}; made worse: {worse}; a sensor fault named as a mechanical effect: {forced}.\n\n"
        + "\n".join(lines)
    )
    print(body)
    if args.docs:
        write_section(
            "Into the end stops: a current gain against an inertia",
            "python -m benchmarks.calibration_stops --docs",
            body,
            DOCS / "calibration.md",
        )


if __name__ == "__main__":
    main()
