"""A rotary actuator's slow window read quasi-statically: its motor's torque k_T·I along the logged speed."""

from __future__ import annotations

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.quasistatic.drive_torque import QuasiStaticReading
from ema.estimate.quasistatic.stretches import Rest, TorqueReading
from ema.model.actuator import ActuatorDocument, RotaryActuator, as_kind
from ema.model.window import RotaryWindow, Window, as_window


def logged_motion(window: Window, gear_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """A rotary window's motion by its logged motor speed, and its hinge moment at the motor (H/n)."""
    s = as_window(window, RotaryWindow).signals
    return s["motor_speed_radps"], s["hinge_moment_nm"] / gear_ratio


def motor_torque(actuator: ActuatorDocument, rest: Rest | None) -> tuple[TorqueReading, Note | None]:
    """A current-piloted motor's torque: k_T·I, signed."""
    params = as_kind(actuator, RotaryActuator).params
    return TorqueReading(1.0 / params.torque_constant_nm_per_a, 0.0, 0.0, 0.0, signed=True), None


MOTOR_READING = QuasiStaticReading(motion=logged_motion, torque=motor_torque)  # the logged speed, k_T·I
