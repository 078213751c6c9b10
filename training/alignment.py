"""The current, the speed and the hinge moment aligned in time: a sensor's filter delays what it logs.

Eq. 5.1 sets the motor torque k_T·I against the inertia's J·dω/dt at each instant; at the shaft's
accelerations both are far larger than the friction read from their difference, so a current
logged a fraction of a millisecond after the speed (an anti-aliasing filter, an averaging ADC, a
speed read through a filtered resolver) leaves a residual that no friction explains. On foreign
windows whose current or speed passed through a 2–8 sample moving average (0.05–0.35 ms of delay),
FDJ and η_O were 7–19 % of the range off on average (up to 59 %), every answer weakly determined.

The lag is read as the shift of the current, to half a sample within ``MAX_LAG_S``, that minimizes
the equation error of the physics fit: batched fits of the window with the current shifted each way
(the sliding samples, set by the speed, stay the same). It is sharp: on those windows the minimum
fell exactly on the filter's delay, the equation error 32–88 % below the unshifted one, and on
windows without filters exactly on zero. A lag is applied only
where it lowers the equation error by ``MIN_GAIN``; then the later of the two signals is advanced
(a filter only delays), by linear interpolation, the end held.

The hinge moment's lag barely shows in the equation error (on most windows lags of 0–3 ms fit it as
well as none), yet through a 1–4 ms strain-gauge filter it put FDJ outside its ±2 std on 18 of 20
windows. It shows in the noise: the filter that delays the signal correlates the noise it passes,
and ``noise_level`` reads that correlation. The delay is read from it (``hinge_lag_samples``; on
20 foreign windows behind 10–40 sample moving averages, 0.70–1.15 of the filter's delay, and
0 on white noise). A strain gauge's noise enters before its amplifier's filter; noise correlated
after an unfiltered signal would be advanced for nothing, so the read is kept only where the
equation error bears it out (no larger than unshifted): on 20 windows each, 19 of the filtered
signals' reads are kept and 6 of the noise-only filters' (whose answers then err by ~5 % of range).
What a misread lag moves FDJ and η_O by goes into their stds (``hinge_lag_spread``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from sim.hinge import denoised_hinge_nm
from sim.window import Window
from training.baseline import FrictionFit, fit_friction
from training.noise_level import MAX_LAG, noise_of
from training.preprocess import as_read

MAX_LAG_S = 1e-3
HALF_STEP = 0.5  # samples: the finest grid searched
MIN_GAIN = 0.05  # the least relative drop of the equation error a lag must bring
MAX_HINGE_LAG_S = 3e-3
# The hinge lag as read from the noise is 0.70–1.15 of a filter's delay (RMS 12 % off on 20 windows), and
# a lag misread moves FDJ: taken as ±15 % (one std) into its std, the physics fit's FDJ held its ±2 std in
# 19 of 20 windows behind 10–40 sample filters, against 15 without.
HINGE_LAG_UNCERTAINTY = 0.15


def advanced(values: np.ndarray, samples: float) -> np.ndarray:
    """``values`` read ``samples`` later (linear interpolation; past the end, the last value)."""
    index = np.arange(len(values), dtype=np.float64)
    return np.interp(index + samples, index, values)


def shifted_fits(
    signals: dict[str, np.ndarray], sample_rate_hz: float, lags: np.ndarray, name: str = "current_a"
) -> FrictionFit:
    """The physics fit with signal ``name`` read ``lags`` samples later, one row per lag, one batched fit."""
    batch = dict(signals, **{name: np.stack([advanced(signals[name], lag) for lag in lags])})
    if name == "hinge_moment_nm":  # its reading leans on the deflection, row by row
        batch["position_deg"] = np.broadcast_to(signals["position_deg"], batch[name].shape)
    read = dict(as_read(batch, sample_rate_hz), position_deg=signals["position_deg"])
    return fit_friction(read, sample_rate_hz)


def equation_errors(
    signals: dict[str, np.ndarray], sample_rate_hz: float, lags: np.ndarray, name: str = "current_a"
) -> np.ndarray:
    """The physics fit's equation error with signal ``name`` read ``lags`` samples later."""
    return shifted_fits(signals, sample_rate_hz, lags, name).residual_rms_nm


def hinge_lag_spread(signals: dict[str, np.ndarray], sample_rate_hz: float, lag: float) -> dict[str, float]:
    """What the hinge lag's read uncertainty (± ``HINGE_LAG_UNCERTAINTY`` of it) leaves in FDJ and η_O: half
    the change of the physics fit across that band, a std to add to theirs."""
    band = lag * (1.0 + HINGE_LAG_UNCERTAINTY * np.array([-1.0, 1.0]))
    fits = shifted_fits(signals, sample_rate_hz, band, "hinge_moment_nm")
    return {"FDJ": float(abs(np.diff(fits.fdj_nm)[0]) / 2), "eta_O": float(abs(np.diff(fits.eta_o)[0]) / 2)}


def current_lag_samples(signals: dict[str, np.ndarray], sample_rate_hz: float) -> float:
    """How many samples the logged current trails the logged speed (negative: the speed trails), 0
    unless that lag lowers the window's equation error by ``MIN_GAIN``: whole samples within
    ``MAX_LAG_S`` first, then half a sample either side of the best, then the parabola's vertex."""
    reach = max(1.0, np.floor(MAX_LAG_S * sample_rate_hz))
    grid = np.arange(-reach, reach + 0.5)
    coarse = equation_errors(signals, sample_rate_hz, grid)
    if not np.all(np.isfinite(coarse)):
        return 0.0  # too little sliding motion: the physics fit says so next
    near = grid[int(np.argmin(coarse))] + np.array([-HALF_STEP, HALF_STEP])
    errors = dict(zip(grid, coarse, strict=True)) | dict(
        zip(near, equation_errors(signals, sample_rate_hz, near), strict=True)
    )
    best = min(errors, key=errors.__getitem__)
    if errors[best] >= (1.0 - MIN_GAIN) * errors[0.0]:
        return 0.0
    if best - HALF_STEP in errors and best + HALF_STEP in errors:  # a filter's delay falls between: the vertex
        below, at, above = (errors[best + d] ** 2 for d in (-HALF_STEP, 0.0, HALF_STEP))
        return float(best + 0.5 * HALF_STEP * (below - above) / (below - 2 * at + above))
    return float(best)


def hinge_lag_samples(signals: dict[str, np.ndarray], sample_rate_hz: float) -> float:
    """How many samples the logged hinge moment trails the load, read from its filter's trace in its
    noise: a filter that leaves the noise T times the low-frequency density of white noise delays
    the signal (T − 1) / 2 samples, exactly for a moving average and a first-order lag."""
    hinge = signals["hinge_moment_nm"]
    difference = hinge - denoised_hinge_nm(hinge, signals["position_deg"], sample_rate_hz)
    _, tau_s = noise_of(difference, sample_rate_hz, MAX_LAG["hinge_moment_nm"], rising_is_noise=True)
    if tau_s == 0.0:
        return 0.0
    rho = float(np.exp(-1.0 / (tau_s * sample_rate_hz)))
    lag = min(rho / (1.0 - rho), MAX_HINGE_LAG_S * sample_rate_hz)  # (T − 1) / 2, T = (1 + ρ) / (1 − ρ)
    unshifted, shifted = equation_errors(signals, sample_rate_hz, np.array([0.0, lag]), "hinge_moment_nm")
    return lag if shifted <= unshifted else 0.0  # noise correlated after an unfiltered signal fits worse


@dataclass(frozen=True)
class Lags:
    """How late each signal was logged [s], undone: the current behind the speed (negative: the speed
    behind the current), the hinge moment behind the load; and the std its read uncertainty adds, per target."""

    current_s: float = 0.0
    hinge_s: float = 0.0
    spread: dict[str, float] = field(default_factory=dict)


def aligned(window: Window) -> tuple[Window, Lags]:
    """``window`` with the later of its current and speed advanced onto the other and its hinge moment
    advanced by its filter's delay, and those lags."""
    rate, signals = window.sample_rate_hz, dict(window.signals)
    current = current_lag_samples(signals, rate)
    if current != 0.0:
        late = "current_a" if current > 0 else "motor_speed_radps"
        signals[late] = advanced(signals[late], abs(current))
    hinge, spread = hinge_lag_samples(signals, rate), {}
    if hinge != 0.0:
        spread = hinge_lag_spread(signals, rate, hinge)
        signals["hinge_moment_nm"] = advanced(signals["hinge_moment_nm"], hinge)
    if current == 0.0 and hinge == 0.0:
        return window, Lags()
    return replace(window, signals=signals), Lags(current / rate, hinge / rate, spread)
