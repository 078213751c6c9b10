"""Bounds on what a window says of itself, in one place and without numpy (the command line's help reads them)."""

from __future__ import annotations

import datetime as dt

IDENTIFIER = r"^[!-~](?:[ -~]{0,198}[!-~])?$"  # printable ASCII, no surrounding blanks: safe in a URL and a CSV
ROUTE_SEGMENTS = ("estimates", "prognosis")  # the service's routes below an actuator: no id may end in one
RELATIVE_SEGMENTS = (".", "..", "")  # segments a browser or a file path resolves away: an id holds none
# Times a trend computes with, bounded where they enter: no airframe flies a million hours, no log predates
# 2000 or is stamped more than a day ahead of the clock that receives it.
MAX_FLIGHT_HOURS = 1_000_000.0
EARLIEST_RECORDED_AT = dt.datetime(2000, 1, 1, tzinfo=dt.UTC)
CLOCK_SKEW = dt.timedelta(days=1)
# The thesis's logging rate: a window's rate where its log names none, and the highest the pipeline reads a
# window at (a faster log is averaged down to it).
DEFAULT_SAMPLE_RATE_HZ = 10_000.0
SAMPLE_RATE_RANGE_HZ = (1_000.0, 100_000.0)  # the rates the simulator draws a window at
DURATION_RANGE_S = (0.01, 60.0)  # the lengths the simulator draws a window at (its samples bounded as well)
MAX_THREADS = 256  # a thread budget's ceiling: more than any onboard computer or server has cores
MIN_SAMPLES = 100
COMMAND_FAMILIES = (
    "thesis",
    "cruise",
    "gust",
    "doublet",
    "steps",
)  # the simulator's commands (the rotary simulator's)
MAX_SAMPLES = 1_000_000
# A window may be logged at 10 Hz (a test rig's logger) to 100 kHz; below HIGH_RATE_HZ it is read quasi-statically
# (``ema.estimate.quasistatic.stretches``), at or above it through the whole pipeline.
WINDOW_RATE_RANGE_HZ = (10.0, 100_000.0)
HIGH_RATE_HZ = 1_000.0
# Physical plausibility: beyond these a sample is a sensor fault or a unit error, not a state.
SIGNAL_LIMITS = {
    "command_deg": (-90.0, 90.0),  # a reference, not a measurement: only a unit error is refused
    "position_deg": (-35.0, 35.0),
    "motor_speed_radps": (-2_000.0, 2_000.0),
    "current_a": (-60.0, 60.0),
    "hinge_moment_nm": (-5_000.0, 5_000.0),
    "command_mm": (-10_000.0, 10_000.0),
    "position_mm": (-10_000.0, 10_000.0),
    "load_n": (-1e6, 1e6),
    "set_point_m": (-100.0, 100.0),
    "position_m": (-100.0, 100.0),
    "drive_force_n": (-1e6, 1e6),
    "set_point_rad": (-100.0, 100.0),  # an output shaft may turn several times
    "position_rad": (-100.0, 100.0),
    "duty_ratio": (-1.0, 1.0),  # a PWM duty: a share of the supply
    "supply_v": (0.0, 1_000.0),  # as logged: a glitch of 0 V or twice the supply is repaired, not refused
    "motor_on_flag": (0.0, 1.0),
}
CONSTANT_NAME = r"^[a-z][a-z0-9_]{0,63}$"
NOISE_COPIES = 30  # noise-only copies of a rotary calibration's windows behind its noise floor
NOISE_COPIES_RANGE = (8, 500)


def route_collision(actuator_id: str) -> str | None:
    """Why ``actuator_id`` would be read as another route of the service (``/v1/actuators/{id}/estimates``), or as
    another actuator's page once a browser resolves it (a segment ``.`` or ``..``: ``a/../b`` opens ``b``'s), or
    None: no segment of it after the first may be a route's name, no segment a relative one, none empty."""
    relative = next((segment for segment in actuator_id.split("/") if segment in RELATIVE_SEGMENTS), None)
    if relative is not None:
        return f"has a segment {relative!r}: a path resolves it to another actuator's (give each part a name)"
    segments = actuator_id.split("/")[1:]
    clash = next((segment for segment in segments if segment in ROUTE_SEGMENTS), None)
    if clash is None:
        return None
    return f"has a segment {clash!r} after its first: /v1/actuators/{{id}}/{clash} is a route of its own"
