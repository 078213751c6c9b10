"""FSJ read at break-away: the one moment the static friction shows in a log.

While the shaft is stuck, dω/dt = 0 and the drive k_T·I + H_e/n is exactly the friction; a slowly
rising drive lifts it until it reaches FSJ + k·|T_ext| and the shaft slips. So the drive at the
end of a rest, minus the load part, is FSJ. Only a *quasi-static* break-away shows it: after a
pilot's step the current reference saturates within microseconds, the drive jumps past the
static level inside one log interval, and the logged drive says nothing about where the shaft
let go (such a doublet read 0.037 N·m against a true 0.094). In flight the position loop keeps
the shaft hunting in the backlash and it rarely rests at all. Hence: an event counts only if the
drive crept up to it, and the answer is a value with a std from the spread of the events, or no
value with the reason.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from sim.params import ActuatorParams, eta_a_from_eta_o
from sim.residual import smoothed
from training.noise_level import white_noise_std

REST_SPEED_RADPS = 0.5  # at rest: the smoothed speed below this (the sensor noise alone exceeds a creep of 1 rad/s)
MIN_RUN_S = 1e-3  # a rest and the motion after it must each last this long
QUASI_STATIC = 0.05  # the drive rose less than this fraction of its level over the last 3 samples of the rest
MIN_RISE_NOISE = 4.0  # ...and by more than this many noise stds over the whole rest
MIN_EVENTS_FOR_STD = 3


@dataclass(frozen=True)
class StaticFriction:
    value_nm: float | None  # FSJ [N·m], or None
    std_nm: float | None
    n_events: int
    reason: str  # how it was read, or why it could not be


def _events(signals: Mapping[str, np.ndarray], rate: float, actuator: ActuatorParams) -> list[tuple[int, float]]:
    """(index, drive) at the end of each rest of ≥ 1 ms, followed by motion of ≥ 1 ms, during which the
    drive was built up against the stuck shaft (it rose by more than its noise, and crept into the end)."""
    speed = np.abs(smoothed(signals["motor_speed_radps"], rate))
    run = max(2, round(MIN_RUN_S * rate))
    rest = speed < REST_SPEED_RADPS
    drive = actuator.torque_constant_nm_per_a * signals["current_a"] + signals["hinge_moment_nm"] / actuator.gear_ratio
    noise = white_noise_std(drive)
    drive = np.abs(np.convolve(drive, np.ones(3) / 3, mode="same"))
    starts = np.flatnonzero(~rest[:-1] & rest[1:]) + 1
    events = []
    for end in np.flatnonzero(rest[:-1] & ~rest[1:]):
        begin = int(starts[starts <= end][-1]) if np.any(starts <= end) else 0
        if end + 1 - begin < run or end + 1 + run > len(rest) or rest[end + 1 : end + 1 + run].any():
            continue  # too short a rest or too short a motion: hunting in passing, not a stick
        peak = end + 1 - run + int(np.argmax(drive[end + 1 - run : end + 2]))
        if peak < 3 or drive[peak] - drive[peak - 3] > QUASI_STATIC * drive[peak]:
            continue  # the drive jumped past the static level: a step, not a break-away
        if drive[peak] - drive[begin : begin + 3].mean() < MIN_RISE_NOISE * noise:
            continue  # a flat drive: the shaft crept (dynamic friction), it was not stuck
        events.append((int(peak), float(drive[peak])))
    return events


def read_static_friction(
    signals: Mapping[str, np.ndarray],
    rate: float,
    fdj_nm: float,
    eta_o: float,
    actuator: ActuatorParams = ActuatorParams(),
) -> StaticFriction:
    """FSJ from the quasi-static break-aways of a window, given its dynamic-friction estimates."""
    events = _events(signals, rate, actuator)
    if not events:
        return StaticFriction(None, None, 0, (
            "no quasi-static break-away in the window: the shaft never rests for 1 ms and then creeps "
            "free (in flight the position loop keeps it hunting in the backlash; after a step the drive "
            "jumps past the static level within one log interval)"
        ))  # fmt: skip
    load = smoothed(signals["hinge_moment_nm"] / actuator.gear_ratio, rate)
    direction = np.sign(smoothed(signals["motor_speed_radps"], rate))
    k_aid, k_opp = 1.0 - float(eta_a_from_eta_o(eta_o)), 1.0 / eta_o - 1.0
    levels = []
    for peak, drive in events:
        moving = direction[min(peak + round(MIN_RUN_S * rate), len(direction) - 1)]
        k = k_aid if load[peak] * moving > 0 else k_opp
        levels.append(drive - k * abs(load[peak]))
    value = float(np.median(levels))
    if value < fdj_nm:
        return StaticFriction(None, None, len(levels), (
            f"{len(levels)} break-away(s) read {value:.4f} N·m, below the dynamic friction {fdj_nm:.4f} N·m: "
            "not a static level (the drive did not build up against a stuck shaft)"
        ))  # fmt: skip
    noise = actuator.torque_constant_nm_per_a * white_noise_std(signals["current_a"]) / np.sqrt(3)
    if len(levels) >= MIN_EVENTS_FOR_STD:
        spread = 1.2533 * float(np.std(levels, ddof=1)) / np.sqrt(len(levels))  # std of a median
        std = max(spread, noise)
    else:
        std = max(noise, 0.1 * value)  # one or two events: no spread to read, so a wide 10 %
    return StaticFriction(value, std, len(levels), f"median of {len(levels)} quasi-static break-away(s)")
