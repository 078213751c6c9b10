"""The geared kind: a DC motor fed by PWM from its supply, a gear train and its own proportional position loop,
logged at the output shaft, swinging a load of known mass and arm (a hobby servo on a pendulum is one).

Its windows go through every stage of the method at the output shaft (``ema.kinds.geared.stages``): the window's
own set point simulated in closed loop by ``ema.kinds.geared.loop`` (the firmware's loop, the motor and its
back-EMF, the pendulum, the gear train's Borello friction with η_O and η_A), the health read by output error, a
network learned from those runs, both assessed, the window simulated at the answer. Its calibration
(``ema.kinds.geared.calibration``) learns the servo's constants over many runs and names what a constant friction
misses.
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
from ema.model.actuator import ActuatorDocument, GearedActuator, actuator_from_dict, as_kind
from ema.model.kinds import KINDS, KindFacts
from ema.model.params import DriveConstants
from ema.model.window import GearedWindow, Window, as_window

ROTARY_STEP_S = DriveConstants().step_s  # what a service's simulation limit counts in
SOLVE_RUNS = 200  # closed-loop runs of the window a reading's solves take, about (physics and its held-out twins)
CALIBRATION_RUNS = 3_000  # closed-loop runs of each window a calibration's solves take, about


@dataclass(frozen=True)
class Geared(LendsNothing):
    facts: KindFacts = KINDS["geared"]

    def stages(self, window: Window) -> tuple[str, ...]:
        return STAGES

    def estimate(self, window: Window, request: Request) -> Estimate:
        from ema.kinds.geared.stages import estimate_geared  # the network's: loaded by its first window

        actuator = as_kind(request.actuator, GearedActuator)
        return estimate_geared(
            as_window(window, GearedWindow),
            request.config,
            actuator=actuator,
            read_with=request.read_with,
            on_stage=request.on_stage,
        )

    def calibrate(self, windows: Sequence[Window], request: CalibrationRequest) -> Calibrated:
        from ema.kinds.geared.calibration_report import calibrate_geared

        actuator = as_kind(request.actuator, GearedActuator)
        report, completed = calibrate_geared(
            [as_window(w, GearedWindow) for w in windows],
            actuator,
            request.config,
            request.on_stage or (lambda _: None),
        )
        return Calibrated(report.model_copy(update={"completed_actuator": completed}), completed)

    def cost(self, window: Window, config: PipelineConfig) -> Cost:
        """Its closed-loop runs (the dataset's, the solves'), one step a logged sample, counted as as many of the
        rotary simulator's 1 µs steps; its window's seconds, which a service's window limit holds."""
        steps = (config.total_simulations + SOLVE_RUNS) * window.n_samples
        return Cost(simulated_s=steps * ROTARY_STEP_S, window_s=window.duration_s)

    def calibration_cost(self, windows: Sequence[Window], config: PipelineConfig) -> Cost:
        """The solves' runs of every window, and each window answered again with the completed document (``cost``)."""
        steps = sum(window.n_samples for window in windows) * CALIBRATION_RUNS
        answered = sum(self.cost(window, config).simulated_s for window in windows)
        return Cost(simulated_s=steps * ROTARY_STEP_S + answered, window_s=sum(window.duration_s for window in windows))

    def synthesize(self, actuator: ActuatorDocument, flags: Mapping[str, Any]) -> dict[str, Any]:
        raise not_drawn(self.facts)

    sensor_gains: tuple[SensorGain, ...] = ()

    def report_lines(self, report: Mapping[str, Any]) -> list[str]:
        """What it learned, its runs' position error before and after, and each load's runs against the nominal."""
        from ema.kinds.geared.calibration_report import report_lines

        return learned_lines(report.get("learned", [])) + report_lines(report)

    def warm_up(self) -> None:
        """A tiny geared servo's window simulated and estimated: its simulator, its solves and its network loaded."""
        from ema.kinds.geared.log_reading import lane_of
        from ema.kinds.geared.loop import Run, simulate_lanes

        actuator = as_kind(actuator_from_dict(WARM_UP_GEARED), GearedActuator)
        rate, n = 100.0, 300
        set_point = 0.8 * np.sin(2 * np.pi * np.arange(n) / rate / 1.5)
        on, supply = np.ones(n, dtype=bool), np.full(n, 12.0)
        run = Run(set_point, on, supply, 16.0, 1.0 / rate, 0.5, 0.01, 0.0)
        lane = lane_of(actuator.geared, {"fdj_nm": 0.1, "eta_o": 0.9, "eta_a": 0.9})
        position = simulate_lanes(run, lane[None, :]).position_rad[0]
        signals = {"set_point_rad": set_point, "position_rad": position, "duty_ratio": np.zeros(n), "supply_v": supply}
        constants = {"position_gain": 16.0, "load_mass_kg": 0.5 / 9.80665 / 0.1, "arm_length_m": 0.1}
        window = Window(signals, rate, None, constants=constants)
        self.estimate(window, Request(WARM_UP, actuator))


WARM_UP_GEARED = {
    "schema": "ema-actuator/1",
    "name": "warm-up",
    "kind": "geared",
    "nominal": {"fdj_nm": 0.1, "eta_o": 0.9, "eta_a": 0.9},
    "geared": {
        "gear_ratio": 300,
        "torque_constant_nm_per_a": 2.5,
        "resistance_ohm": 6.0,
        "inertia_kg_m2": 0.02,
        "error_gain_per_rad": 0.2,
        "viscous_nm_s_per_rad": 0.02,
        "position_resolution_rad": 0.0015,
    },
}


GEARED = Geared()
