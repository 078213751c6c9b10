"""The servo kind: a linear axis driven by a force command from a known position controller, logged on the load
side (the EMPS benchmark's machine is one).

Its windows go through every stage of the method in the load frame (``ema.kinds.servo.stages``): its own set point
simulated in closed loop by ``ema.kinds.servo.closed_loop``, a network learned from those runs, both estimators
assessed, the window simulated at the answer. Its calibration (``ema.kinds.servo.calibration``) learns the load's
constants and traces what the model still misses to a named effect.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import STAGES, Estimate
from ema.kinds.base import (
    WARM_UP,
    Calibrated,
    CalibrationRequest,
    Cost,
    LendsNothing,
    Request,
    SensorGain,
    learned_lines,
    not_drawn,
)
from ema.kinds.servo.calibration import CLOSED_LOOPS, calibrate_servo
from ema.kinds.servo.closed_loop import SUBSTEPS, ServoLoop, simulate_servo
from ema.model.actuator import ActuatorDocument, ServoActuator, actuator_from_dict, as_kind
from ema.model.kinds import KINDS, KindFacts
from ema.model.params import DriveConstants
from ema.model.window import ServoWindow, Window, as_window

ROTARY_STEP_S = DriveConstants().step_s  # what a service's simulation limit counts in


@dataclass(frozen=True)
class Servo(LendsNothing):
    facts: KindFacts = KINDS["servo"]

    def stages(self, window: Window) -> tuple[str, ...]:
        return STAGES

    def estimate(self, window: Window, request: Request) -> Estimate:
        from ema.kinds.servo.stages import (
            estimate_servo,
        )  # the network's: loaded by its first window (ema.kinds.rotary)

        actuator = as_kind(request.actuator, ServoActuator)
        return estimate_servo(
            as_window(window, ServoWindow),
            request.config,
            actuator=actuator,
            read_with=request.read_with,
            on_stage=request.on_stage,
        )

    def calibrate(self, windows: Sequence[Window], request: CalibrationRequest) -> Calibrated:
        report, completed, plot = calibrate_servo(
            [as_window(w, ServoWindow) for w in windows], as_kind(request.actuator, ServoActuator)
        )
        return Calibrated(report.model_copy(update={"completed_actuator": completed}), completed, plot)

    def cost(self, window: Window, config: PipelineConfig) -> Cost:
        """Its simulations' load steps, counted as as many of the rotary simulator's 1 µs steps (a lane-step of
        either costs a few ns); its window's seconds, which a service's window limit holds as it holds any kind's."""
        steps = (config.total_simulations + 1) * window.n_samples * SUBSTEPS
        return Cost(simulated_s=steps * ROTARY_STEP_S, window_s=window.duration_s)

    def calibration_cost(self, windows: Sequence[Window], config: PipelineConfig) -> Cost:
        steps = sum(window.n_samples * SUBSTEPS * CLOSED_LOOPS for window in windows)
        return Cost(simulated_s=steps * ROTARY_STEP_S, window_s=sum(window.duration_s for window in windows))

    def synthesize(self, actuator: ActuatorDocument, flags: Mapping[str, Any]) -> dict[str, Any]:
        raise not_drawn(self.facts)

    sensor_gains: tuple[SensorGain, ...] = ()

    def report_lines(self, report: Mapping[str, Any]) -> list[str]:
        """What it learned, beside it as the simulator takes it (``as_simulated``)."""
        simulated = {entry["name"]: entry["value"] for entry in report.get("as_simulated", [])}
        return learned_lines(report.get("learned", []), simulated)

    def warm_up(self) -> None:
        """A tiny servo's window (``WARM_UP_SERVO``) simulated and estimated: its filters, its simulator and its
        network exercised once (their kernels loaded)."""
        from ema.kinds.servo.loop_dataset import lane_parameters

        loop = WARM_UP_LOOP
        rate = 1.0 / loop.period_s
        set_point = 0.05 * np.sin(2 * np.pi * np.arange(round(2.0 * rate)) / rate)  # 2 s, a stroke each way
        run = simulate_servo(set_point, lane_parameters(WARM_UP_LOAD)[None, :], loop)
        window = Window(
            {"set_point_m": set_point, "position_m": run.position_m[0], "drive_force_n": run.drive_force_n[0]},
            rate,
            None,
            constants={
                "position_gain_per_s": loop.position_gain_per_s,
                "speed_gain_per_mps": loop.speed_gain_per_mps,
                "drive_gain_n_per_unit": loop.drive_gain_n_per_unit,
            },
        )
        self.estimate(window, Request(WARM_UP, actuator_from_dict(WARM_UP_SERVO)))


WARM_UP_SERVO = {
    "schema": "ema-actuator/1",
    "name": "warm-up",
    "kind": "servo",
    "servo": {},  # its controller's gains the window's, its rate the window's
}
WARM_UP_LOOP = ServoLoop(160.0, 240.0, 35.0, np.inf, 1e-3, 0.0)  # kp, kv, gain, no limit, 1 kHz, exact position
WARM_UP_LOAD = {"mass_kg": 90.0, "viscous_ns_per_m": 200.0, "fdj_n": 20.0, "offset_n": 0.0}


SERVO = Servo()
