"""Eq. 5.1 on the load side: a servo's inverse dynamic model, solved by least squares (IDIM-LS).

A servo's log holds the force its drive applied and the motion it caused, both on the load. The force is
what moved the load:

    F = M·q̈ + FDJ·sgn(q̇) + C·q̇ + F_offset + F_load                              (Eq. 5.1, load frame)

linear in the constants once q̇ and q̈ are known. They come from the measured position: a zero-phase
4th-order Butterworth low-pass at ``CUTOFF_BANDWIDTHS`` times the closed loop's bandwidth, then central
differences. The equation holds at every sample, but its noise (the controller's answer to the position's
quantization, the drive's ripple) lives far above the motion: every column and the force are decimated
alike (an 8th-order Chebyshev low-pass at 0.8 of the new Nyquist rate, zero phase, then every r-th sample)
down to ``DECIMATED_BANDWIDTHS`` times the bandwidth. This is Gautier's IDIM-LS practice, and what the EMPS
benchmark's own identification does, so its error 100·‖y − ŷ‖/‖y‖ is comparable with the published one.

The residual is not white (a misfit at each reversal spans many decimated samples), so the least-squares
std would claim several times what a second run of the same machine can confirm; the std here is
Newey–West's, which weighs the residual's own correlation (``NEWEY_WEST_LAGS``).

A force the log does not carry (a push on the load, a disturbance injected into the drive) shows as residual far
beyond what the model leaves at that sample: more than ``DISTURBANCE_SIGMAS`` times the larger of the window's
own robust noise and the RMS residual its simulations leave at that row (they share its command, so they show
where the model itself struggles: a break-away, a reversal). Those rows, and their neighbours within the
decimation filter's reach, are left out (``disturbed_rows``).

Columns beyond the four (a viscous coefficient per direction, a Stribeck term) are the model's effects
(``inverse_columns``), named as the calibration names them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ema.estimate.least_squares import MIN_OFFSET_BALANCE, coefficients, newey_west_std
from ema.estimate.stats import rms, robust_variance, white_noise_std
from ema.kinds.servo.zero_phase import butter_lowpass, cheby1_lowpass, filtfilt
from ema.model.checks import InputError

FILTER_ORDER = 4  # the position's Butterworth low-pass
CUTOFF_BANDWIDTHS = 5.0  # its cutoff, in loop bandwidths
DECIMATED_BANDWIDTHS = 2.0  # the decimation's anti-alias edge, in loop bandwidths
DECIMATION_RIPPLE_DB = 0.05  # the Chebyshev's pass-band ripple (MATLAB's decimate)
DECIMATION_ORDER = 8
EDGE_CUTOFF_PERIODS = 5.0  # the filters' transients at either end, left out of the solution
REST_STEPS_PER_SAMPLE = 2.0  # a filtered speed under this many sensor steps a sample: the load rests (dithers)
REST_SHARE_OF_TOP = 0.002  # the same, for a sensor without a step: this share of the top speed
REST_MARGIN_DECIMATIONS = 2  # a decimated row this near a rest (in decimation factors) is left out too
MIN_TRAVEL_NOISES = 20.0  # a load whose filtered travel is under this many position-noise stds never moved
DISTURBANCE_SIGMAS = 8.0  # a residual this far past what the model leaves there is a force the log lacks
DISTURBANCE_MARGIN_ROWS = 3  # its neighbours, which the decimation filter smeared it into
POLYNOMIAL_ORDER = 3  # an effect along the stroke: Legendre polynomials up to this order
BASE = ("mass_kg", "viscous_ns_per_m", "fdj_n", "offset_n")
UNITS = {
    "mass_kg": "kg",
    "viscous_ns_per_m": "N·s/m",
    "viscous_up_ns_per_m": "N·s/m",
    "viscous_down_ns_per_m": "N·s/m",
    "fdj_n": "N",
    "offset_n": "N",
    "stribeck_n": "N",
    "stribeck_speed_mps": "m/s",
    "presliding_n": "N",
    "presliding_travel_m": "m",
    **{f"position_{kind}_p{k}_n": "N" for kind in ("force", "friction") for k in range(1, POLYNOMIAL_ORDER + 1)},
    "turn_ripple_sin_n": "N",
    "turn_ripple_cos_n": "N",
}
EITHER_SIGN = frozenset(
    name for name in UNITS if name == "offset_n" or name.startswith(("position_", "turn_ripple_"))
)  # constants of either sign: an offset, a force along the stroke or the motor's turn


@dataclass(frozen=True)
class Motion:
    """The load's motion as the solution reads it, full rate, the filters' transients at both ends left out (samples
    ``first`` to ``first + len``)."""

    position_m: np.ndarray
    speed_mps: np.ndarray
    acceleration_mps2: np.ndarray
    first: int  # the first sample of the window these arrays start at
    decimation: int  # r: every r-th sample of the decimated columns
    sliding: np.ndarray  # (rows,) bool: the decimated rows where the load slides (at rest, static friction holds it)

    @property
    def samples(self) -> slice:
        """The window's samples these arrays cover."""
        return slice(self.first, self.first + len(self.speed_mps))


def _butter_lowpass(rate_hz: float, cutoff_hz: float) -> tuple[np.ndarray, np.ndarray]:
    return butter_lowpass(FILTER_ORDER, min(cutoff_hz / (rate_hz / 2.0), 0.99))


def _filtfilt(b: np.ndarray, a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Zero-phase filtering, its start-up padded as MATLAB's filtfilt pads (3·(order) samples, odd reflection)."""
    return filtfilt(b, a, x, padlen=3 * (max(len(a), len(b)) - 1))


def central_difference(values: np.ndarray, rate_hz: float) -> np.ndarray:
    """dv/dt by central differences, one-sided at the two ends."""
    out = np.empty_like(values)
    out[1:-1] = (values[2:] - values[:-2]) / 2.0
    out[0], out[-1] = values[1] - values[0], values[-1] - values[-2]
    return out * rate_hz


def load_motion(position_m: np.ndarray, rate_hz: float, bandwidth_hz: float, resolution_m: float = 0.0) -> Motion:
    """The filtered position, its speed and acceleration (module docstring), past the filters' start-up, and the
    decimated rows where the load slides: Eq. 5.1's sgn(q̇)·FDJ holds only there (a load at rest is held by
    whatever static friction balances the force, and its filtered speed is the sensor's dither), so a row within
    ``REST_MARGIN_DECIMATIONS`` of a rest is left out."""
    cutoff = CUTOFF_BANDWIDTHS * bandwidth_hz
    decimation = max(1, round(0.8 * (rate_hz / 2.0) / (DECIMATED_BANDWIDTHS * bandwidth_hz)))
    edge = max(round(EDGE_CUTOFF_PERIODS * rate_hz / cutoff) - 1, 1)
    if len(position_m) - 2 * edge < 20 * decimation:
        raise InputError("signals.position_m", f"{len(position_m)} samples are too few to read its motion from")
    kept = slice(edge, len(position_m) - edge)
    filtered = _filtfilt(*_butter_lowpass(rate_hz, cutoff), position_m)
    speed = central_difference(filtered, rate_hz)[kept]
    acceleration = central_difference(central_difference(filtered, rate_hz), rate_hz)[kept]
    top = float(np.max(np.abs(speed)))
    rest = REST_STEPS_PER_SAMPLE * resolution_m * rate_hz if resolution_m > 0 else REST_SHARE_OF_TOP * top
    resting = np.abs(speed) <= rest  # a log that never moves rests throughout (rest 0)
    margin = REST_MARGIN_DECIMATIONS * decimation
    near_rest = np.convolve(resting, np.ones(2 * margin + 1), mode="same") > 0
    rows = decimated_indices(len(speed), decimation)
    return Motion(filtered[kept], speed, acceleration, edge, decimation, ~near_rest[rows])


def refuse_still(motion: Motion, position_m: np.ndarray) -> None:
    """Raise unless a logged window's load travels (``motion``'s filtered position) beyond its sensor's noise (read
    on ``position_m``, the log's): a window at rest holds no sliding friction, and a no-step sensor's noise would
    otherwise pass for motion (its rest is a share of the top speed). The window's own check: its simulations
    follow its set point."""
    travel, noise_m = float(np.ptp(motion.position_m)), white_noise_std(position_m)
    if travel <= MIN_TRAVEL_NOISES * noise_m:
        raise InputError(
            "signals.position_m",
            f"travels {travel:.3g} m, within {MIN_TRAVEL_NOISES:g} times its noise ({noise_m:.3g} m): the load "
            "never slides, and friction shows only in motion",
        )


def decimated_indices(n: int, factor: int) -> np.ndarray:
    """The samples ``decimated`` keeps of ``n``: every ``factor``-th, aligned on the last."""
    begin = factor - (factor * -(-n // factor) - n)
    return np.arange(begin - 1, n, factor) if factor > 1 else np.arange(n)


def decimated(values: np.ndarray, factor: int) -> np.ndarray:
    """Every ``factor``-th sample after a zero-phase anti-alias low-pass, aligned on the last sample (as MATLAB's
    ``decimate``): what every column and the force go through alike."""
    if factor == 1:
        return values
    b, a = cheby1_lowpass(DECIMATION_ORDER, DECIMATION_RIPPLE_DB, 0.8 / factor)
    return _filtfilt(b, a, values)[decimated_indices(len(values), factor)]


def travel_since_reversal(speed: np.ndarray, position: np.ndarray) -> np.ndarray:
    """|q − q at the last change of the motion's sign| at each sample (from the first sample before any)."""
    sign = np.sign(speed)
    held = np.maximum.accumulate(np.where(sign != 0, np.arange(len(sign)), 0))
    direction = sign[held]
    starts = np.zeros(len(sign), dtype=int)
    change = np.flatnonzero(np.diff(direction) != 0) + 1
    starts[change] = change
    return np.abs(position - position[np.maximum.accumulate(starts)])


def _legendre(position: np.ndarray) -> list[np.ndarray]:
    """P1..P``POLYNOMIAL_ORDER`` of the position over the stroke the window covers."""
    x = 2.0 * (position - position.min()) / max(float(np.ptp(position)), 1e-12) - 1.0
    return [np.polynomial.legendre.Legendre.basis(k)(x) for k in range(1, POLYNOMIAL_ORDER + 1)]


def inverse_columns(motion: Motion, effects: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
    """The model's columns at full rate: M, C, FDJ, the offset, and each effect in ``effects`` (name -> its
    nonlinear constant, ``ema.kinds.servo.load_effects`` says what each is): ``viscous_down`` splits C by
    direction; ``stribeck`` (v_S) adds sgn(q̇)·exp(−(q̇/v_S)²); ``presliding`` (σ) adds −sgn(q̇)·exp(−s/σ), s the
    travel since the last reversal; ``position_force`` adds P1..P3 of the position, ``position_friction``
    sgn(q̇)·P1..P3; ``turn_ripple`` (p, the travel per turn) sin(2π·q/p) and cos(2π·q/p)."""
    v, q = motion.speed_mps, motion.position_m
    sign = np.sign(v)
    columns = {"mass_kg": motion.acceleration_mps2, "viscous_ns_per_m": v, "fdj_n": sign, "offset_n": np.ones_like(v)}
    effects = effects or {}
    if "viscous_down" in effects:
        del columns["viscous_ns_per_m"]
        columns = {"viscous_up_ns_per_m": v * (v > 0), "viscous_down_ns_per_m": v * (v < 0), **columns}
    if "stribeck" in effects:
        columns["stribeck_n"] = sign * np.exp(-((v / effects["stribeck"]) ** 2))
    if "presliding" in effects:
        columns["presliding_n"] = -sign * np.exp(-travel_since_reversal(v, q) / effects["presliding"])
    if "position_force" in effects:
        columns |= {f"position_force_p{k}_n": p for k, p in enumerate(_legendre(q), start=1)}
    if "position_friction" in effects:
        columns |= {f"position_friction_p{k}_n": sign * p for k, p in enumerate(_legendre(q), start=1)}
    if "turn_ripple" in effects:
        angle = 2.0 * np.pi * q / effects["turn_ripple"]
        columns |= {"turn_ripple_sin_n": np.sin(angle), "turn_ripple_cos_n": np.cos(angle)}
    return columns


@dataclass(frozen=True)
class InverseSolution:
    """Eq. 5.1 solved: each constant with its Newey–West std, the error as the benchmark states it."""

    values: dict[str, float]
    stds: dict[str, float]
    error_pct: float  # 100·‖y − ŷ‖/‖y‖ on the decimated force
    residual_rms_n: float  # RMS of that residual
    samples: int  # decimated samples solved
    residual_by_row: np.ndarray  # (rows,) over every decimated row: the residual where solved, NaN elsewhere


def decimated_problem(
    force_n: np.ndarray, columns: Mapping[str, np.ndarray], motion: Motion, left_out: np.ndarray | None = None
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The force and every column decimated alike, on the rows where the load slides (less ``left_out``)."""
    rows = motion.sliding if left_out is None else motion.sliding & ~left_out
    y = decimated(force_n, motion.decimation)[rows]
    return y, {name: decimated(column, motion.decimation)[rows] for name, column in columns.items()}


def disturbed_rows(residual_by_row: np.ndarray, simulated_by_row: np.ndarray) -> np.ndarray:
    """(rows,) bool: where a window's residual (``InverseSolution.residual_by_row``) exceeds ``DISTURBANCE_SIGMAS``
    times the larger of its robust noise and its simulations' RMS residual at the row (``simulated_by_row``, (K, rows)),
    and the rows beside them (module docstring)."""
    solved = np.isfinite(residual_by_row)
    r = residual_by_row[solved]
    noise = float(np.sqrt(robust_variance(r))) if len(r) else 0.0
    envelope = np.zeros(len(residual_by_row))
    if len(simulated_by_row):
        seen = np.isfinite(simulated_by_row).any(
            axis=0
        )  # a row no simulation solved has no envelope: the noise sets it
        envelope[seen] = np.sqrt(np.nanmean(simulated_by_row[:, seen] ** 2, axis=0))
    scale = np.fmax(envelope, noise)
    far = solved & (np.abs(np.nan_to_num(residual_by_row)) > DISTURBANCE_SIGMAS * np.maximum(scale, 1e-300))
    return np.convolve(far, np.ones(2 * DISTURBANCE_MARGIN_ROWS + 1), mode="same") > 0


def solve_inverse(
    force_n: np.ndarray, columns: Mapping[str, np.ndarray], motion: Motion, left_out: np.ndarray | None = None
) -> InverseSolution:
    """Least squares of the force on ``columns`` (full rate, one length), both decimated, on the rows where the
    load slides, less ``left_out`` (a disturbance's: ``disturbed_rows``)."""
    y, decimated_columns = decimated_problem(force_n, columns, motion, left_out)
    names = list(decimated_columns)
    x = np.column_stack([decimated_columns[name] for name in names])
    if len(y) < 4 * len(names):
        raise InputError("signals.position_m", f"the load slides in {len(y)} of the decimated samples: too few to read")
    rarer = min(int(np.sum(decimated_columns["fdj_n"] > 0)), int(np.sum(decimated_columns["fdj_n"] < 0)))
    if rarer < MIN_OFFSET_BALANCE * len(y):
        raise InputError(
            "signals.position_m",
            f"the load slides the other way in {rarer} of {len(y)} decimated samples: moving one way, its friction "
            "FDJ·sgn(q̇) and the force's offset are one column, and a window must move both ways to tell them apart",
        )
    beta = coefficients(x, y)
    residual = y - x @ beta
    stds = newey_west_std(x, residual)
    by_row = np.full(len(motion.sliding), np.nan)
    by_row[motion.sliding if left_out is None else motion.sliding & ~left_out] = residual
    return InverseSolution(
        values=dict(zip(names, beta.tolist(), strict=True)),
        stds=dict(zip(names, stds.tolist(), strict=True)),
        error_pct=float(100.0 * np.linalg.norm(residual) / max(float(np.linalg.norm(y)), 1e-300)),
        residual_rms_n=rms(residual),
        samples=len(y),
        residual_by_row=by_row,
    )
