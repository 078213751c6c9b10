"""Which field an inconsistent window names: the relations of ``ema.kinds.rotary.prepare.consistency`` read together.

A relation that fails alone points to one field; some fail together for one cause (a speed of the other
sign breaks the kinematics and reads Eq. 5.1 against the motion), so the order of the checks and the
readings beside each failure decide which field the refusal names. A travel gain a logger's rate setting
explains is the sample rate, one a unit explains is that unit, any other the document's gear ratio.
"""

from __future__ import annotations

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.information import too_few_levels
from ema.kinds.rotary.prepare.consistency import (
    FOLLOW_GAP_DEG,
    FOLLOW_STEP_S,
    READINGS,
    Consistency,
    consistency,
    out_of_step,
)
from ema.model.checks import InputError
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

TRAVEL_GAIN = (0.9, 1.1)  # g accepted
NOTED_GAIN = (0.98, 1.02)  # g accepted without a note: a working drive's position and speed agree within it
MIN_FOLLOWING = 0.8  # share of the judged steps (consistency.following) toward the command, accepted
UNIT_SLIPS = (  # a travel gain of about (factor): the field, and the slip it points to
    (1.0 / np.degrees(1.0), "signals.position_deg", "in radians (or motor_speed_radps in deg/s)?"),
    (np.pi / 30.0, "signals.motor_speed_radps", "in rpm?"),
)
UNIT_SLIP_TOLERANCE = 0.1
# A sample rate stated off by a factor a logger's settings make (a decimation, a base rate, kHz for Hz) is taken
# for the cause; a travel gain of any other factor is an actuator of another gear ratio than its document's.
RATE_SLIPS = (2.0, 0.5, 4.0, 0.25, 5.0, 0.2, 10.0, 0.1, 1.024, 1 / 1.024, 1e3, 1e-3)
RATE_SLIP_TOLERANCE = 0.02
AGAINST_THE_MOTION = ("current sign", "torque signs")  # readings that say the motor's motion runs backwards


def check_logged(window: RotaryWindow) -> None:
    """An InputError naming the first sensor with fewer than three distinct values over ``window``
    (``ema.estimate.information.too_few_levels``, the rule every kind's channels are held to), its load's too."""
    for name in ("position_deg", "motor_speed_radps", "current_a", "hinge_moment_nm"):
        why = too_few_levels(window.signals[name])
        if why is not None:
            raise InputError(f"signals.{name}", why)


def kinematics_note(found: Consistency) -> list[Note]:
    """What a kinematic gain outside ``NOTED_GAIN`` may mean, for the result's notes."""
    gain = found.travel_gain
    if gain is None or NOTED_GAIN[0] <= gain <= NOTED_GAIN[1]:
        return []
    text = (
        f"the position travels {gain:.3f}x the speed's integral / gear ratio (1 in a consistent log): the sample "
        "rate, the speed's or the position's gain is that far off; read as logged (a time base off puts J·dω/dt off "
        "as much)"
    )
    return [Note(code="kinematic_gain", text=text)]


def _travel_error(
    gain: float, reading: tuple[str, float] | None, loop: str, window: RotaryWindow, drive: DriveConstants
) -> InputError:
    """The error for a travel gain outside ``TRAVEL_GAIN``, naming the field it points to: for a sign, the
    speed where Eq. 5.1 reads the torques against the motion (24–940x better flipped), else the position
    (a command near 0° is followed by either sign: it cannot tell); otherwise a known unit slip, or the
    sample rate."""
    travel = (
        f"the position's travel is {gain:.3g}x the speed's integral over the window / gear ratio "
        f"{drive.gear_ratio:g} (1 in a working drive){loop}"
    )
    if gain < 0 and reading is not None and reading[0] in AGAINST_THE_MOTION:
        return InputError("signals.motor_speed_radps", f"runs against position_deg and the torques: {travel}: a sign?")
    if gain < 0:
        return InputError("signals.position_deg", f"runs against motor_speed_radps: {travel}: a sign?")
    unit = next(
        ((field, slip) for factor, field, slip in UNIT_SLIPS if abs(gain / factor - 1.0) < UNIT_SLIP_TOLERANCE), None
    )
    rate = window.sample_rate_hz
    rate_slip = any(abs(gain / factor - 1.0) < RATE_SLIP_TOLERANCE for factor in RATE_SLIPS)
    if unit is not None and rate_slip:  # a logger's rate setting matches more closely than a unit (2 % against 10 %)
        return InputError(
            "sample_rate_hz",
            f"is {rate:.6g} Hz, but {travel}: at {rate / gain:.6g} Hz it would be 1 "
            f"(a rate stated {gain:.3g}x the log's?); or {unit[0].split('.')[-1]} {unit[1]}",
        )
    if unit is not None:
        return InputError(unit[0], f"{unit[1]} {travel}")
    if rate_slip:
        return InputError(
            "sample_rate_hz",
            f"{travel}: at {rate / gain:.6g} Hz instead of {rate:.6g} it would be 1 (a rate stated "
            f"{gain:.3g}x the log's?); or is motor_speed_radps in other units, or the document's gear ratio off?",
        )
    return InputError(
        "actuator.drive.gear_ratio",
        f"{travel}: the drive that logged this window turns as a gear ratio of {drive.gear_ratio / gain:.4g} "
        f"would; is the actuator's document the right one (its gear ratio, k_T, end stops)? Else the sample rate "
        f"is off (at {rate / gain:.6g} Hz instead of {rate:.6g} it would be 1) or motor_speed_radps is in other "
        "units",
    )


def check_consistency(window: RotaryWindow, drive: DriveConstants) -> Consistency:
    """``window``'s relations, or an InputError naming the field the failing ones point to."""
    check_logged(window)
    found = consistency(window, drive)
    gain, follows, reading = found.travel_gain, found.following, found.better_reading
    lost = follows is not None and follows < MIN_FOLLOWING
    loop = (
        ""
        if follows is None
        else f"; the position moves toward the command in {100 * follows:.0f} % of the {FOLLOW_STEP_S * 1e3:g} ms "
        f"steps begun over {FOLLOW_GAP_DEG:g}° from it (97–100 % in a working closed loop)"
    )
    if gain is not None and not TRAVEL_GAIN[0] <= gain <= TRAVEL_GAIN[1]:
        raise _travel_error(gain, reading, loop, window, drive)
    if lost and reading is not None and reading[0] in AGAINST_THE_MOTION:
        raise InputError(
            "signals.position_deg",
            f"and motor_speed_radps both run against the command and the current{loop}: a sign convention?",
        )
    if lost:
        raise InputError(
            "signals.command_deg",
            f"the position does not follow it{loop}: a command in other units, of the other sign or of another window?",
        )
    shifted = out_of_step(window, drive)
    if shifted is not None:
        name, lag_s, better = shifted
        raise InputError(
            f"signals.{name}",
            f"is out of step with the other channels: Eq. 5.1 explains the window {better:.3g}x better with it read "
            f"{1e3 * lag_s:+g} ms later (a sensor's filter delays ~1 ms at most): exported on another clock?",
        )
    if reading is not None:
        _, name, meaning = READINGS[reading[0]]
        unseen = " (or position_deg and motor_speed_radps have: the command moves too little to tell which)"
        meaning += unseen if follows is None and reading[0] == "torque signs" else ""
        raise InputError(f"signals.{name}", f"{meaning}: Eq. 5.1 explains the window {reading[1]:.3g}x better so")
    return found
