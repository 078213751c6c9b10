"""What a slow window's drive current says of the motor's torque, by the kind of drive (``QuasiStaticReading``): a
current-piloted motor's k_T·I along its logged speed, or a stepper's (I − I0)/c along its set point, with how its
healthy runs scattered as ``ema calibrate`` learned it. A kind (``ema.kinds``) passes its reading to
``ema.estimate.quasistatic.slow_window``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.quasistatic.stretches import Repeatability, Rest, TorqueReading, logged_motion, set_point_motion
from ema.model.actuator import ActuatorDocument, LinearActuator
from ema.model.checks import InputError
from ema.model.screw import Screw
from ema.model.window import Window

REST_DEPARTURE = 4.0  # a window's current at rest this many day-to-day spreads off the document's: said


def screw_of(actuator: ActuatorDocument) -> Screw | None:
    """The document's screw, what a stepper's current is read through; None for a kind without one (a rotary
    actuator's window read quasi-statically)."""
    return actuator.screw if isinstance(actuator, LinearActuator) else None


def motor_torque(actuator: ActuatorDocument, rest: Rest | None) -> tuple[TorqueReading, Note | None]:
    """A current-piloted motor's torque: k_T·I, signed."""
    return TorqueReading(1.0 / actuator.params.torque_constant_nm_per_a, 0.0, 0.0, 0.0, signed=True), None


def stepper_torque(actuator: ActuatorDocument, rest: Rest | None) -> tuple[TorqueReading, Note | None]:
    """A stepper drive's torque along the motion, (I − I0)/c, and a note where the window's current at rest
    departs from the document's current at zero torque.

    Its current at zero torque is the document's, learned over healthy runs, its std their spread: a window's own
    reading at rest scatters by more than its noise from one stop to the next (where the motor comes to rest
    within a step) and tells nothing of its current while it moves, so it only checks the document (a drive
    whose zero-torque current moved: recalibrate)."""
    screw = screw_of(actuator)
    if screw is None or screw.current_per_nm_a is None or screw.current_at_zero_torque_a is None:
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


@dataclass(frozen=True)
class QuasiStaticReading:
    """What a kind reads a slow window by: its motion and load (``ema.estimate.quasistatic.stretches``), and what its
    drive's current says of the torque."""

    motion: Callable[[Window, float], tuple[np.ndarray, np.ndarray]]
    torque: Callable[[ActuatorDocument, Rest | None], tuple[TorqueReading, Note | None]]
    spread: Callable[[ActuatorDocument], Repeatability] = lambda _: Repeatability()


def screw_spread(actuator: ActuatorDocument) -> Repeatability:
    """How a screw's healthy runs scattered, as its document learned it."""
    screw = screw_of(actuator)
    if screw is None:
        return Repeatability()
    return Repeatability(screw.run_to_run_nm, screw.run_noise_nm or 0.0, screw.repeatability_nm or 0.0)


MOTOR_READING = QuasiStaticReading(motion=logged_motion, torque=motor_torque)  # the logged speed, k_T·I
STEPPER_READING = QuasiStaticReading(motion=set_point_motion, torque=stepper_torque, spread=screw_spread)
