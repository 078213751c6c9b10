"""A linear actuator's window read quasi-statically: a stepper's torque along its set point, (I − I0)/c, through the
drive its healthy runs taught (``ema.kinds.linear.drive_calibration``), and how those runs scattered."""

from __future__ import annotations

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.quasistatic.drive_torque import HealthyRuns, QuasiStaticReading
from ema.estimate.quasistatic.stretches import Repeatability, Rest, TorqueReading
from ema.model.actuator import ActuatorDocument, LinearActuator, as_kind
from ema.model.checks import InputError
from ema.model.window import LinearWindow, Window, as_window


def set_point_motion(window: Window, gear_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """A linear window's motion by its set point's speed (exact where a potentiometer's is noise) and its load
    torque at the motor in the positive direction (F·lead/2π = F/n)."""
    s = as_window(window, LinearWindow).signals
    return np.gradient(s["command_mm"]) * window.sample_rate_hz, s["load_n"] / gear_ratio


REST_DEPARTURE = 4.0  # a window's current at rest this many day-to-day spreads off the document's: said
FELL = "friction lost (a ball screw losing its preload: a spalled track, smaller balls)"
ROSE = "friction gained (grease lost, a seal tightened, a track roughened)"


def stepper_torque(actuator: ActuatorDocument, rest: Rest | None) -> tuple[TorqueReading, Note | None]:
    """A stepper drive's torque along the motion, (I − I0)/c, and a note where the window's current at rest
    departs from the document's current at zero torque.

    Its current at zero torque is the document's, learned over healthy runs, its std their spread: a window's own
    reading at rest scatters by more than its noise from one stop to the next (where the motor comes to rest
    within a step) and tells nothing of its current while it moves, so it only checks the document (a drive
    whose zero-torque current moved: recalibrate)."""
    screw = as_kind(actuator, LinearActuator).screw
    if screw.current_per_nm_a is None or screw.current_at_zero_torque_a is None:
        raise InputError(
            "actuator.screw.current_per_nm_a",
            "is not known yet: a stepper's current per N·m and its "
            "current at zero torque are on no data sheet; run ema calibrate on healthy runs at two loads "
            "(--out-actuator) and read with that document",
        )
    spread = screw.current_at_zero_torque_std_a or 0.0
    reading = TorqueReading(
        screw.current_per_nm_a, screw.current_per_nm_std_a or 0.0, screw.current_at_zero_torque_a, spread, signed=False
    )
    if rest is None or abs(rest.current_a - screw.current_at_zero_torque_a) <= REST_DEPARTURE * max(spread, 1e-9):
        return reading, None
    note = Note(
        code="current_at_zero_torque",
        parameter="current_a",
        text=(
            f"at rest the drive draws {rest.current_a:.3f} A, {REST_DEPARTURE:g} or more of its day-to-day spreads "
            f"from the {screw.current_at_zero_torque_a:.3f} ± {spread:.3f} A the document learned: its zero-torque "
            "current may have moved (another day, another drive setting); FDJ counts it as friction until ema "
            "calibrate is rerun on healthy runs"
        ),
    )
    return reading, note


def screw_spread(actuator: ActuatorDocument) -> Repeatability:
    """How a screw's healthy runs scattered, as its document learned it."""
    screw = as_kind(actuator, LinearActuator).screw
    return Repeatability(screw.run_to_run_nm, screw.run_noise_nm or 0.0, screw.repeatability_nm or 0.0)


def screw_healthy(actuator: ActuatorDocument) -> HealthyRuns:
    """What a screw's healthy runs taught beside its drive: η_O's std, a healthy set's spread, their loads."""
    screw = as_kind(actuator, LinearActuator).screw
    return HealthyRuns(screw.eta_o_std or 0.0, screw.healthy_set_nm, screw.calibrated_loads_n, FELL, ROSE)


STEPPER_READING = QuasiStaticReading(
    motion=set_point_motion, torque=stepper_torque, spread=screw_spread, healthy=screw_healthy
)
