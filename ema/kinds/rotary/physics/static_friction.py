"""FSJ read at break-away: the one moment the static friction shows in a log.

While the shaft is stuck, dω/dt = 0 and the drive k_T·I + H_e/n is exactly the friction; a slowly
rising drive lifts it until it reaches FSJ + k·|T_ext| and the shaft slips. So the drive at the
end of a rest, minus the load part, is FSJ. Only a *quasi-static* break-away shows it, and a rest
counts as one only if

- the drive *crept* into the break-away: after a pilot's step the current reference saturates
  within microseconds and the drive jumps past the static level inside one log interval;
- the drive did not jump *as the shaft let go* either: a shaft held still against the hinge load
  and then stepped away shows a drive that is only a lower bound of the static level;
- the shaft was stuck, not creeping: its mean speed over the rest is zero within the noise (a
  shaft creeping at 0.3 rad/s under dynamic friction passes for resting in a noisy log);
- it was clear of the end stops, where the drive is the stop's reaction, not friction;
- the drive rose over the rest by more than its noise (a flat drive: no build-up).

The smoothed speed leaves "rest" a little after the shaft does (its kernel, the noise), so the
break-away is sought over the last ``LOOKBACK_RUNS`` ms of the rest. The answer is the median of
the events with a std from their spread, or no value with the reason. The log holds interval means:
where the drive itself scatters before the break-away (a loop that dithers the current on its own
noisy speed reading), the peak that let the shaft go hides inside an interval, up to two of the
scatter's stds above the ramp, so no event is read closer than that.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ema.estimate.documents import Note
from ema.estimate.stats import white_noise_std
from ema.kinds.rotary.simulator.residual import END_STOP_MARGIN_DEG, smoothed
from ema.model.noise import NO_NOISE, SensorNoise
from ema.model.params import DriveConstants, load_factors

REST_SPEED_RADPS = 0.5  # at rest: the smoothed speed below this (the sensor noise alone exceeds a creep of 1 rad/s)
MIN_RUN_S = 1e-3  # a rest and the motion after it must each last this long
STILL_SHARE = 0.05  # the drive moves less than this share of its level in the 3 samples into a break-away, or 1 ms out
MIN_RISE_NOISE = 4.0  # noise stds: how far the drive must rise over a rest; the allowance of the jump and creep tests
MIN_EVENTS_FOR_STD = 3
LOOKBACK_RUNS = 3  # the break-away is sought over the last 3 MIN_RUN_S of a rest
DITHER_STDS = 2.0  # a dithering drive lets the shaft go at a peak up to 2 of its stds above the ramp


@dataclass(frozen=True)
class StaticFriction:
    value_nm: float | None  # FSJ [N·m], or None
    std_nm: float | None
    n_events: int
    reason: Note  # how it was read, or why it could not be


def _rests(speed_radps: np.ndarray, run: int) -> list[tuple[int, int]]:
    """(first, last) sample of each rest of ≥ ``run`` samples that is followed by ≥ ``run`` samples of motion."""
    rest = speed_radps < REST_SPEED_RADPS
    starts = np.flatnonzero(~rest[:-1] & rest[1:]) + 1
    out = []
    for end in np.flatnonzero(rest[:-1] & ~rest[1:]):
        begin = int(starts[starts <= end][-1]) if np.any(starts <= end) else 0
        if end + 1 - begin >= run and end + 1 + run <= len(rest) and not rest[end + 1 : end + 1 + run].any():
            out.append((begin, int(end)))
    return out


@dataclass(frozen=True)
class _Event:
    """One quasi-static break-away."""

    index: int
    drive_nm: float  # |drive| (3-sample mean) as the shaft let go
    scatter_nm: float  # the drive samples' std about their ramp before it


@dataclass(frozen=True)
class _Traces:
    """What a break-away is read from: the drive |k_T·I + H_e/n| (3-sample means) and the raw speed, each
    with its per-sample noise std, the deflection, and the signed drive per sample (its scatter)."""

    drive_nm: np.ndarray
    drive_noise_nm: float
    speed_radps: np.ndarray
    speed_noise_radps: float
    position_deg: np.ndarray
    signed_drive_nm: np.ndarray


def _lookback_start(rest: tuple[int, int], run: int) -> int:
    """The first sample of the rest's last ``LOOKBACK_RUNS`` runs, where its break-away is sought."""
    return max(rest[0], rest[1] + 1 - LOOKBACK_RUNS * run)


def _break_away(t: _Traces, rest: tuple[int, int], run: int, end_stop_deg: float) -> int | None:
    """The sample where the drive, built up against the stuck shaft, let it go; None if this rest shows no
    quasi-static break-away (module docstring)."""
    begin, end = rest
    drive, noise = t.drive_nm, t.drive_noise_nm
    first = _lookback_start(rest, run)
    peak = first + int(np.argmax(drive[first : end + 2]))
    level = drive[peak]
    tolerance = 3 * noise * np.sqrt(2 / 3)  # 3 std of the difference of two 3-sample means
    if peak < 3 or level - drive[peak - 3] > STILL_SHARE * level + tolerance:
        return None  # the drive jumped into the break-away: a step
    if drive[end + 1 : end + 1 + run].max() > (1 + STILL_SHARE) * level + MIN_RISE_NOISE * noise:
        return None  # it jumped as the shaft let go: the rest's drive only bounds the static level
    inside = t.speed_radps[begin + run // 2 : end + 1 - run]  # the rest but its ends, where the motion leaks in
    if len(inside) < 2 or abs(inside.mean()) > MIN_RISE_NOISE * t.speed_noise_radps / np.sqrt(len(inside)):
        return None  # the shaft crept (dynamic friction), or rested too briefly to tell
    if np.abs(t.position_deg[begin : end + 1 + run]).max() >= end_stop_deg - END_STOP_MARGIN_DEG:
        return None  # against an end stop the drive is the stop's reaction
    if level - drive[begin : begin + 3].mean() < MIN_RISE_NOISE * noise:
        return None  # a flat drive: nothing was built up
    return peak


def _scatter(drive_nm: np.ndarray, begin: int, peak: int) -> float:
    """The std of the (signed) drive's samples about a smooth ramp (a parabola) over ``[begin, peak]``: the
    least uncertainty of a level read from interval means while the drive scatters like that."""
    if peak - begin < 5:
        return 0.0
    t = np.arange(begin, peak + 1, dtype=np.float64) - peak
    residual = drive_nm[begin : peak + 1] - np.polyval(np.polyfit(t, drive_nm[begin : peak + 1], 2), t)
    return float(np.sqrt(np.sum(residual**2) / (len(t) - 3)))


def _traces(signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants, noise: SensorNoise) -> _Traces:
    """The torque and speed with the per-sample std that *white* noise would need to scatter their means as
    much as this window's does: a sensor filter correlates the noise, and its means scatter more. Read
    white, a filtered torque's noise looks like build-ups, and each reads as a low FSJ."""
    torque = drive.torque_constant_nm_per_a * signals["current_a"] + signals["hinge_moment_nm"] / drive.gear_ratio
    speed = signals["motor_speed_radps"]
    drive_noise = max(white_noise_std(torque), drive.torque_constant_nm_per_a * noise.current_a)
    speed_noise = max(white_noise_std(speed), noise.motor_speed_radps, 0.01)  # a noiseless log still has a resolution
    rho_speed = noise.correlation("motor_speed_radps", rate)
    return _Traces(
        drive_nm=np.abs(np.convolve(torque, np.ones(3) / 3, mode="same")),
        drive_noise_nm=drive_noise * noise.mean_inflation("current_a", 3, rate),
        speed_radps=speed,
        speed_noise_radps=speed_noise * float(np.sqrt((1 + rho_speed) / (1 - rho_speed))),  # of long means
        position_deg=signals["position_deg"],
        signed_drive_nm=torque,
    )


def _events(signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants, noise: SensorNoise) -> list[_Event]:
    """Each quasi-static break-away: a rest of ≥ 1 ms, then motion of ≥ 1 ms."""
    run = max(2, round(MIN_RUN_S * rate))
    traces = _traces(signals, rate, drive, noise)
    events = []
    for rest in _rests(np.abs(smoothed(traces.speed_radps, rate)), run):
        peak = _break_away(traces, rest, run, drive.end_stop_deg)
        if peak is not None:
            scatter = _scatter(traces.signed_drive_nm, _lookback_start(rest, run), peak)
            events.append(_Event(peak, float(traces.drive_nm[peak]), scatter))
    return events


def read_static_friction(
    signals: Mapping[str, np.ndarray],
    rate: float,
    fdj_nm: float,
    eta_o: float,
    drive: DriveConstants,
    noise: SensorNoise = NO_NOISE,
) -> StaticFriction:
    """FSJ from the quasi-static break-aways of a window, given its dynamic-friction estimates and its
    measured sensor noise (``NO_NOISE``: the traces' own white-noise level alone)."""
    events = _events(signals, rate, drive, noise)
    if not events:
        return StaticFriction(
            None,
            None,
            0,
            Note(
                code="fsj_no_break_away",
                parameter="FSJ",
                text=(
                    "no quasi-static break-away in the window: the shaft never rests for 1 ms and then creeps "
                    "free (where the position loop holds the surface it hunts in the backlash; after a step the "
                    "drive jumps past the static level within one log interval)"
                ),
            ),
        )
    load = smoothed(signals["hinge_moment_nm"] / drive.gear_ratio, rate)
    direction = np.sign(smoothed(signals["motor_speed_radps"], rate))
    k_aid, k_opp = (float(k) for k in load_factors(float(eta_o), drive.gear_ratio))
    levels = []
    for event in events:
        moving = direction[min(event.index + round(MIN_RUN_S * rate), len(direction) - 1)]
        k = k_aid if load[event.index] * moving > 0 else k_opp
        levels.append(event.drive_nm - k * abs(load[event.index]))
    value = float(np.median(levels))
    if value < fdj_nm:
        return StaticFriction(
            None,
            None,
            len(levels),
            Note(
                code="fsj_below_fdj",
                parameter="FSJ",
                text=(
                    f"{len(levels)} break-away(s) read {value:.4f} N·m, below the dynamic friction {fdj_nm:.4f} N·m: "
                    "not a static level (the drive did not build up against a stuck shaft)"
                ),
            ),
        )
    current_noise = max(white_noise_std(signals["current_a"]) / np.sqrt(3), noise.mean_std("current_a", 3, rate))
    sensor = drive.torque_constant_nm_per_a * current_noise
    floor = max(sensor, DITHER_STDS * float(np.median([event.scatter_nm for event in events])))
    if len(levels) >= MIN_EVENTS_FOR_STD:
        spread = 1.2533 * float(np.std(levels, ddof=1)) / np.sqrt(len(levels))  # std of a median
        std = max(spread, floor)
    else:
        std = max(floor, 0.1 * value)  # one or two events: no spread to read, so a wide 10 %
    text = f"median of {len(levels)} quasi-static break-away(s)"
    return StaticFriction(value, std, len(levels), Note(code="fsj_read", parameter="FSJ", text=text))
