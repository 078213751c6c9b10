"""Whether a window's signals tell one story: a sign convention, a unit or a sample rate the log got
wrong, found and named before anything is read from the window.

A careless export (a speed or current of the other sign, a sample rate twice the log's, a hinge
moment in kN·m) otherwise gets an answer ranges off, said weak but an answer. Three relations hold
in every window of a working drive, whatever its health:

1. Kinematics: the surface turns as the motor does, θ_u = θ_m / n behind the backlash's dead band.
   The position is ``g`` times the speed's integral over n carried through a dead band
   (``simulator.dead_band``, its width solved: a worn band as well); a working drive reads g within a
   percent of 1. A speed of the other sign gives g = −1, a sample rate stated twice the log's g = 2,
   a position in radians 1/57.3.
   Refused outside ``verdict.TRAVEL_GAIN``: a position sensor's gain a few % off is no unit error.
2. The closed loop: the surface moves toward the command whenever it is over ``FOLLOW_GAP_DEG`` away.
   Over 2 ms steps, begun on the side of the command the surface has been on for the drive's reaction
   time (``reaction_s``: the thesis's needs ~20 ms to turn from full speed), a working loop does so in
   nearly every step; a position of the other sign or a command in radians fails it in many. Judged
   over ``MIN_FOLLOW_S`` of such steps.
3. Eq. 5.1: the current drives the motion against friction and load. Read with the current's sign
   flipped, the hinge moment's, both (which is the motion's sign flipped), or the hinge moment read
   from kN·m, lbf·in or lbf·ft, the window's solution (a sensor offset free) is ``MIN_BETTER`` times
   better only if that field is wrong. A load 0.74x (lbf·ft) is much what η_O 0.74x as high reads
   (Eq. 5.1's load term), and seldom told; what is missed, the check still flags.

4. One clock: a sensor's filter logs it up to ~1 ms late (``ema.kinds.rotary.prepare.alignment`` reads
   that), but a channel exported out of step by 5–20 ms puts FDJ ranges off. Where Eq. 5.1 explains
   ``MIN_BETTER`` times better with the current or the hinge moment read ``STEP_LAGS_S`` away, the
   window is refused naming it and the lag.

Before these, every sensor must show that it logs: a working one shows at least three
values over a window (its noise, its quantization). A hinge moment logged as zeros (an aircraft
without the strain gauge) or stuck at one value would be read as a load of nothing. The command
may hold still.

Which field is named follows from which relations fail together (``ema.kinds.rotary.prepare.verdict``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import solve_friction
from ema.kinds.rotary.physics.shifts import shifted_solutions
from ema.kinds.rotary.prepare.departures.zero_offset import OFFSET_SOLVE
from ema.kinds.rotary.simulator.dead_band import dead_band_paths
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow

BAND_GRID = 40  # dead band widths tried: 0, then geometric from 5 % of the document's to the whole travel
MIN_EXPLAINED = 0.9  # share of the position's variance the speed's travel must explain for g to be judged
FOLLOW_GAP_DEG = 1.0
FOLLOW_STEP_S = 2e-3
FOLLOW_MIN_STEP_DEG = 0.05  # a step that moves: 5 position-noise stds
REACTION_MARGIN = 1.3  # a drive turns from full speed one way to the other in J_M·2ω_max / T_M,max: this once more
MIN_FOLLOW_S = 0.01  # of steps over the gap, to judge the loop by
STEP_LAGS_S = np.array([-50, -20, -10, -5, -3, 3, 5, 10, 20, 50]) * 1e-3  # channel lags tried, beyond any filter
MIN_BETTER = 3.0  # how many times better a reading of a field must follow Eq. 5.1 to call the field wrong
READINGS = {  # fields read otherwise: ({signal: factor}, the field named, what it would mean)
    "current sign": (
        {"current_a": -1.0},
        "current_a",
        "its sign is the other one: it opposes the torque the motion needs",
    ),
    "hinge sign": (
        {"hinge_moment_nm": -1.0},
        "hinge_moment_nm",
        "its sign is the other one: the load aids where it opposes",
    ),
    "hinge in kN·m": ({"hinge_moment_nm": 1e3}, "hinge_moment_nm", "it is 1000x too small: in kN·m?"),
    "hinge in lbf·in": ({"hinge_moment_nm": 0.11298}, "hinge_moment_nm", "it is 8.85x too large: in lbf·in?"),
    "hinge in lbf·ft": ({"hinge_moment_nm": 1.35582}, "hinge_moment_nm", "it is 0.738x too small: in lbf·ft?"),
    # Eq. 5.1 is odd in (I, H) against (ω, θ): both torques flipped is the motion flipped, which the command tells
    "torque signs": (
        {"current_a": -1.0, "hinge_moment_nm": -1.0},
        "current_a",
        "and hinge_moment_nm both have the other sign: they oppose the motion",
    ),
}


@dataclass(frozen=True)
class Consistency:
    """How a window's signals relate (None: too little motion to judge that relation)."""

    travel_gain: float | None  # the position's travel over the speed's integral / n (1: consistent)
    following: float | None  # share of the steps over the gap that move toward the command
    better_reading: tuple[str, float] | None  # a field read otherwise (``READINGS``), and how many times better


def _best_band(travel: np.ndarray, y: np.ndarray, halves: np.ndarray) -> tuple[float, float, int]:
    """Over dead bands of ``halves`` (each begun at either face or the middle), the one whose path best
    explains ``y`` (centred): (explained sum of squares, slope, its index in ``halves``)."""
    starts = np.repeat([-1.0, 0.0, 1.0], len(halves))
    paths = dead_band_paths(travel, np.tile(halves, 3), starts)
    paths -= paths.mean(axis=1, keepdims=True)
    spread, covariance = np.einsum("ij,ij->i", paths, paths), paths @ y
    explained = np.divide(covariance**2, spread, out=np.zeros_like(spread), where=spread > 0.0)
    best = int(np.argmax(explained))
    slope = covariance[best] / spread[best] if spread[best] > 0.0 else 0.0
    return float(explained[best]), float(slope), best % len(halves)


def travel_gain(window: RotaryWindow, drive: DriveConstants) -> float | None:
    """The drive's kinematic gain g: the least-squares slope (with an intercept) of the position (rad) on
    the speed's integral / n carried through a dead band (``simulator.dead_band``) whose width (any the travel
    shows: a worn band too; a coarse grid, then a fine one about the best) and start the least squares
    choose; None where that explains under ``MIN_EXPLAINED`` of the position's variance (a surface that
    hardly moves, or not with the motor)."""
    rate, position = window.sample_rate_hz, np.radians(window.signals["position_deg"])
    travel = np.cumsum(window.signals["motor_speed_radps"]) / rate / drive.gear_ratio
    y = position - position.mean()
    widest = max(float(np.ptp(travel)), drive.backlash_rad)
    if widest <= 0.0:
        return None  # the motor never turned: no travel to read a gain from
    narrowest = 0.05 * (drive.backlash_rad if drive.backlash_rad > 0 else 0.01 * widest)  # a band new or worn
    coarse = np.concatenate([[0.0], np.geomspace(narrowest, widest, BAND_GRID - 1)]) / 2
    at = _best_band(travel, y, coarse)[2]
    fine = np.linspace(coarse[max(0, at - 1)], coarse[min(len(coarse) - 1, at + 1)], BAND_GRID)
    explained, gain, _ = _best_band(travel, y, fine)
    return gain if explained >= MIN_EXPLAINED * (y @ y) > 0.0 else None


def reaction_s(drive: DriveConstants) -> float:
    """How long the drive takes to turn from full speed one way to full speed the other, with a margin (the
    thesis's: 19 ms, taken as 25)."""
    turn = drive.inertia_kgm2 * 2 * drive.max_motor_speed_radps / drive.max_motor_torque_nm
    return REACTION_MARGIN * turn


def following(window: RotaryWindow, drive: DriveConstants) -> float | None:
    """The share of ``FOLLOW_STEP_S`` steps, begun over ``FOLLOW_GAP_DEG`` from the command (clipped to the
    end stops) on the side it has stood for the drive's reaction time (``reaction_s``) and moving, that move
    toward it; None where they
    last under ``MIN_FOLLOW_S`` in all."""
    position, rate = window.signals["position_deg"], window.sample_rate_hz
    command = np.clip(window.signals["command_deg"], -drive.end_stop_deg, drive.end_stop_deg)
    lag = max(1, round(FOLLOW_STEP_S * rate))
    step, gap = position[lag:] - position[:-lag], (command - position)[:-lag]
    side, at = np.sign(gap), np.arange(len(gap))
    since = at - np.maximum.accumulate(np.where(np.diff(side, prepend=side[0]) != 0, at, 0))  # on this side
    judged = (np.abs(gap) > FOLLOW_GAP_DEG) & (np.abs(step) > FOLLOW_MIN_STEP_DEG) & (since >= reaction_s(drive) * rate)
    if judged.sum() < MIN_FOLLOW_S * rate:
        return None
    return float(np.mean(np.sign(step[judged]) == side[judged]))


def better_reading(window: RotaryWindow, drive: DriveConstants) -> tuple[str, float] | None:
    """The reading of ``READINGS`` that follows Eq. 5.1 best, with how many times its equation error is below
    the window's as logged, if by ``MIN_BETTER``; one batched solution of the window and its readings."""
    signals, rate = window.signals, window.sample_rate_hz
    batch = {name: np.stack([signals[name]] * (1 + len(READINGS))) for name in ("current_a", "hinge_moment_nm")}
    for row, (factors, _, _) in enumerate(READINGS.values(), start=1):
        for name, factor in factors.items():
            batch[name][row] = signals[name] * factor
    batch["position_deg"] = np.broadcast_to(signals["position_deg"], batch["current_a"].shape)
    read = dict(as_read(dict(signals, **batch), rate), position_deg=signals["position_deg"])
    errors = solve_friction(read, rate, drive, OFFSET_SOLVE).residual_rms_nm
    gains = errors[0] / errors[1:]
    best = int(np.nanargmax(gains)) if np.any(np.isfinite(gains)) else -1
    if best < 0 or not gains[best] >= MIN_BETTER:
        return None
    return list(READINGS)[best], float(gains[best])


def step_lags(window: RotaryWindow) -> np.ndarray:
    """``STEP_LAGS_S`` in samples of ``window``, those under a quarter of it (the rest must overlap)."""
    lags = STEP_LAGS_S * window.sample_rate_hz
    return lags[np.abs(lags) < window.n_samples / 4]


def out_of_step(window: RotaryWindow, drive: DriveConstants) -> tuple[str, float, float] | None:
    """The channel (current or hinge moment), its lag [s] and how many times better Eq. 5.1 explains with it,
    where a lag of ``STEP_LAGS_S`` explains it ``MIN_BETTER`` times better than none; else None."""
    signals, rate, lags = window.signals, window.sample_rate_hz, step_lags(window)
    if not len(lags):
        return None
    logged = float(solve_friction(as_read(signals, rate), rate, drive).residual_rms_nm[0])
    for name in ("current_a", "hinge_moment_nm"):
        errors = shifted_solutions(dict(signals), rate, lags, drive, name).residual_rms_nm
        best = int(np.nanargmin(errors)) if np.any(np.isfinite(errors)) else -1
        if best >= 0 and logged >= MIN_BETTER * errors[best]:
            return name, float(lags[best] / rate), logged / float(errors[best])
    return None


def consistency(window: RotaryWindow, drive: DriveConstants) -> Consistency:
    """The three relations of the module docstring, read off ``window``."""
    return Consistency(travel_gain(window, drive), following(window, drive), better_reading(window, drive))
