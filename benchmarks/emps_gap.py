"""What is left between the EMPS log and its model once calibrated: noise, or something the model lacks?
(docs/results.md)

The estimation run read with the model ``ema calibrate`` completes on it twice (four effects). Its set point is
periodic: one motion repeated, so the inverse model's residual at a row and at the same row a period later differ
by what does not repeat (noise), beside the same parts of its noise-only copies' residual. What repeats beyond
theirs is a function of the motion that the model lacks; a map along the stroke solved on two periods shows that one
motion repeated cannot tell what that function follows.

    python -m benchmarks.emps_gap [--docs]
"""

from __future__ import annotations

import argparse

import numpy as np

from benchmarks.emps import calibrations, estimation_run
from benchmarks.foreign_accuracy import RESULTS_MD
from ema.cli.benchmark_docs import typed_command, write_section
from ema.estimate import thread_budget
from ema.estimate.stats import rms
from ema.kinds.servo.inverse import decimated_problem, inverse_columns, solve_inverse
from ema.kinds.servo.log_reading import ServoPrepared, prepare_servo
from ema.kinds.servo.stacked_solve import noise_copies, problem, solved
from ema.model.actuator import ServoActuator, as_kind

TITLE = "What is left of the EMPS log: a motion the model lacks, repeated with the set point"
MIN_PERIOD_S = 1.0
KNOTS = 160  # the map along the stroke tried: hat functions on this many knots, a force and a friction on each
SAME_SHARE = 1e-6  # a set point within this share of its stroke, RMS, of itself a lag later repeats there


def period(set_point_m: np.ndarray) -> int | None:
    """The shortest lag [samples] past ``MIN_PERIOD_S`` after which the set point repeats itself (within
    ``SAME_SHARE`` of its stroke, RMS), None where it never does."""
    same = SAME_SHARE * float(np.ptp(set_point_m))
    for lag in range(int(MIN_PERIOD_S * 1000), len(set_point_m) // 2):
        if rms(set_point_m[lag:] - set_point_m[:-lag]) <= same:
            return lag
    return None


def _repeat_parts(residual_by_row: np.ndarray, rows: int) -> tuple[float, float, float, float]:
    """(RMS, correlation with itself ``rows`` later, RMS of what does not repeat (the difference over √2), RMS of
    what does) of a residual by decimated row (NaN where unsolved)."""
    a, b = residual_by_row[:-rows], residual_by_row[rows:]
    both = np.isfinite(a) & np.isfinite(b)
    whole = rms(residual_by_row[np.isfinite(residual_by_row)])
    apart = rms(a[both] - b[both]) / np.sqrt(2.0)
    return whole, float(np.corrcoef(a[both], b[both])[0, 1]), apart, float(np.sqrt(max(whole**2 - apart**2, 0.0)))


def reading(log: tuple[float, ...], floor: tuple[float, ...]) -> str:
    """What the table says, in words, from its figures."""
    return (
        "Reading it. The log's residual repeats with its motion, as its noise-only copies' does: theirs is the "
        "controller's hold and the sensor's steps, both set by the motion; the log's repeating part is "
        f"{log[3] / floor[3]:.1f} times theirs. What does not repeat is the log's own noise beyond its sensor's steps "
        f"({log[2]:.2f} against {floor[2]:.2f} N: a drive's noise, a vibration), small beside it. So the equation "
        "error above the floor is mostly a function of the motion that the model's effects lack, the same in every "
        "period. One motion repeated cannot tell what it follows: a map of the force and of the friction along the "
        f"stroke (hat functions on {KNOTS} knots) solved on two periods predicts the first nearly as well as it fits "
        "them (below), because it is the same motion (tried, not adopted: memory, not a model). A log of another "
        "motion of the machine, such as the held-out run, can tell which."
    )


def repeat_lines(prepared: ServoPrepared, lag: int) -> list[str]:
    """The log's residual against itself a period later, beside its noise-only copies' (the median of them), and
    what that says."""
    model = dict(prepared.effects)
    motion = prepared.motion
    rows = lag // motion.decimation
    log = _repeat_parts(solve_inverse(prepared.force_n, inverse_columns(motion, model), motion).residual_by_row, rows)
    copies = noise_copies([prepared], solved(problem([prepared], model)), model).by_row[0]
    floor = np.median([_repeat_parts(copy, rows) for copy in copies], axis=0)
    names = ("residual, RMS [N]", "correlation with itself a period later", "what does not repeat, RMS [N]",
             "what repeats, RMS [N]")  # fmt: skip
    rows_said = [f"| {n} | {x:.2f} | {y:.2f} |" for n, x, y in zip(names, log, floor, strict=True)]
    return [*rows_said, "", reading(log, tuple(floor))]


def map_lines(prepared: ServoPrepared, lag: int) -> list[str]:
    """The model with a map along the stroke (``KNOTS`` hat functions, as a force and as a friction) solved on the log's
    second and third periods: its error there and on the first period, beside the model's without the map."""
    motion = prepared.motion
    columns = inverse_columns(motion, dict(prepared.effects))
    centres = np.linspace(motion.position_m.min(), motion.position_m.max(), KNOTS)
    sign = np.sign(motion.speed_mps)
    for i, centre in enumerate(centres[1:]):  # the first left out: the offset is their sum
        hat = np.clip(1.0 - np.abs(motion.position_m - centre) / (centres[1] - centres[0]), 0.0, None)
        columns |= {f"force_{i}": hat, f"friction_{i}": sign * hat}
    y, x = decimated_problem(prepared.force_n, columns, motion)
    sample = (motion.first + motion.decimation * np.arange(len(motion.sliding)))[motion.sliding]
    first, solved_on = sample < lag, (sample >= lag) & (sample < 3 * lag)
    lines = []
    for label, names in (
        ("the model", [n for n in x if not n.startswith(("force_", "friction_"))]),
        ("with the map", list(x)),
    ):
        design = np.column_stack([x[n] for n in names])
        beta = np.linalg.lstsq(design[solved_on], y[solved_on], rcond=None)[0]
        errors = [100 * np.linalg.norm(y[r] - design[r] @ beta) / np.linalg.norm(y[r]) for r in (solved_on, first)]
        lines.append(f"| {label} | {len(names)} | {errors[0]:.2f} % | {errors[1]:.2f} % |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/results.md")
    args = parser.parse_args()
    thread_budget.configure(None)
    window = estimation_run()
    document = as_kind(calibrations(window, 2)[-1], ServoActuator)
    prepared = prepare_servo(window, document)
    lag = period(window.signals["set_point_m"])
    assert lag is not None, "the EMPS set point is periodic"
    body = [
        f"The estimation run, read with the model `ema calibrate` completes on it twice ("
        f"{', '.join(['viscous_down', *document.servo.effects])}). Its set point is one motion of {lag / 1000:.2f} s, "
        f"repeated: the inverse model's residual at each row against the same row a period later.",
        "",
        "| the inverse model's residual | the log | its noise-only copies |",
        "|---|---:|---:|",
        *repeat_lines(prepared, lag),
        "",
        "The map tried, solved on the second and third periods: the inverse error there and on the first period.",
        "",
        "| model | constants | error, periods 2-3 | error, period 1 |",
        "|---|---:|---:|---:|",
        *map_lines(prepared, lag),
    ]
    text = "\n".join(body)
    print(text)
    if args.docs:
        write_section(TITLE, typed_command(), text, RESULTS_MD)


if __name__ == "__main__":
    main()
