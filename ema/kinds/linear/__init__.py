"""The linear kind: a ball screw turned by a stepper, logged by a rig at its own rate.

Its windows are read quasi-statically at any rate (``ema.estimate.quasistatic.slow_window``: the stepper's drive is no
current loop ema can simulate), its torque from the drive's current as ``ema calibrate`` learned it
(``ema.kinds.linear.drive_calibration``): healthy runs teach the drive, faulted runs are compared with it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import Estimate
from ema.estimate.quasistatic.slow_window import QUASI_STATIC_STAGES
from ema.kinds.base import (
    Calibrated,
    CalibrationRequest,
    Cost,
    LendsNothing,
    Request,
    SensorGain,
    not_drawn,
    read_quasi_statically,
)
from ema.kinds.linear.calibration_report import calibrate_linear
from ema.kinds.linear.stepper_reading import STEPPER_READING
from ema.model.actuator import ActuatorDocument, LinearActuator, as_kind
from ema.model.kinds import KINDS, KindFacts
from ema.model.window import LinearWindow, Window, as_window


@dataclass(frozen=True)
class Linear(LendsNothing):
    facts: KindFacts = KINDS["linear"]

    def stages(self, window: Window) -> tuple[str, ...]:
        return QUASI_STATIC_STAGES

    def estimate(self, window: Window, request: Request) -> Estimate:
        return read_quasi_statically(window, request, STEPPER_READING)

    def calibrate(self, windows: Sequence[Window], request: CalibrationRequest) -> Calibrated:
        report, completed, plot = calibrate_linear(
            [as_window(w, LinearWindow) for w in windows], as_kind(request.actuator, LinearActuator)
        )
        return Calibrated(report.model_copy(update={"completed_actuator": completed}), completed, plot)

    def cost(self, window: Window, config: PipelineConfig) -> Cost:
        return Cost(simulated_s=0.0, window_s=0.0)  # no simulation: its samples alone bound the work

    def calibration_cost(self, windows: Sequence[Window], config: PipelineConfig) -> Cost:
        return Cost(simulated_s=0.0, window_s=0.0)

    def synthesize(self, actuator: ActuatorDocument, flags: Mapping[str, Any]) -> dict[str, Any]:
        raise not_drawn(self.facts)

    sensor_gains: tuple[SensorGain, ...] = ()

    def report_lines(self, report: Mapping[str, Any]) -> list[str]:
        """What its healthy runs taught of its drive, or what its faulted runs changed."""
        from ema.kinds.linear.calibration_report import report_lines

        return report_lines(report)

    def warm_up(self) -> None:
        """Nothing: a stepper's window is read quasi-statically in NumPy, milliseconds from the first."""


LINEAR = Linear()
