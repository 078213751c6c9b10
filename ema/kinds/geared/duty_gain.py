"""The loop's gain read off the duty the servo logged: g, the duty per rad of error per unit of kp, at a command
delay.

The firmware applies d = kp·g·(r(t − τ_d) − q) (+ its minimum duty, the way the error points) and the recorder logs
that duty. So g is a reading, not a fit: each run's logged duty regressed on kp·(r(t − τ_d) − q) and the error's
sign over its unsaturated samples with the motor on, and the median of the runs' slopes. It depends on the delay:
read with none, a servo that gets its set point late seems to answer a smaller error the stiffer its loop; read at
the delay it has, one gain holds at every kp. A calibration starts its solves there, and reports the reading at the
delay it names beside the gain it solves (the solve's absorbs what the model's one step a sample leaves of the
firmware's faster loop).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

UNSATURATED = 0.8  # a logged duty above this share of its largest is left out (the limit bends the line)
MIN_SAMPLES = 20  # a run with fewer unsaturated samples with the motor on reads no gain


@dataclass(frozen=True)
class LoggedDuty:
    """One run's logged duty (N,) beside its set point and position (N,), its gain kp and sample step [s]."""

    duty_ratio: np.ndarray
    set_point_rad: np.ndarray
    position_rad: np.ndarray
    motor_on: np.ndarray
    position_gain: float
    step_s: float


def gain_at(runs: Sequence[LoggedDuty], delay_s: float) -> tuple[float, float]:
    """(g, its std) at ``delay_s``: each run's logged duty regressed on kp·error and sgn(error), the median of the
    runs' slopes (a run whose duty the limit bends, or whose error a slip throws, moves a mean, not a median), its
    std the runs' robust spread over √(runs)."""
    slopes = []
    for run in runs:
        t = np.arange(len(run.set_point_rad)) * run.step_s
        error = run.position_gain * (np.interp(t - delay_s, t, run.set_point_rad) - run.position_rad)
        largest = float(np.max(np.abs(run.duty_ratio), initial=0.0))
        kept = run.motor_on & (np.abs(run.duty_ratio) < UNSATURATED * largest) & (error != 0)
        if kept.sum() >= MIN_SAMPLES:
            columns = np.column_stack([error[kept], np.sign(error[kept])])
            slopes.append(np.linalg.lstsq(columns, run.duty_ratio[kept], rcond=None)[0][0])
    if not slopes:
        return 0.0, 0.0
    centre = float(np.median(slopes))
    spread = 1.4826 * float(np.median(np.abs(np.array(slopes) - centre))) / np.sqrt(len(slopes))
    return centre, spread
