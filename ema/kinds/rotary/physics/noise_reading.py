"""How noisy a measured window is, and how its noise is correlated, so that training sees what the
estimator will see.

The noise is read from the difference between the window and a clean simulation of it (the hinge
moment: its own denoised reading, ``ema.kinds.rotary.simulator.hinge``, since the simulations feel the logged load),
through its second difference at each lag L up to ``MAX_LAG`` samples: for stationary noise of
autocovariance R,

    S(L) = Var(x[k+L] − 2·x[k] + x[k−L]) = 6·R(0) − 8·R(L) + 2·R(2L)

which reaches its plateau 6·R(0) once L passes the noise's correlation. The difference's smooth
part (timing, the loop's own small departures) grows as L⁴ and stays out of the small lags that
are used; a robust (MAD) variance ignores the few samples where the motion turns sharply.

What the estimates feel is the noise's low-frequency density, R(0)·T with T = 1 + 2·Σ R(k)/R(0)
(1 when white). The area between the plateau and S is Σ (6R(0) − S(L)) = 8·ΣR(k) − 2·ΣR(2k),
between 7 and 8 times ΣR(k) for any correlation shape, so T is read from it without assuming one
(summed over the lags before S first reaches ``1 − DIP`` of its plateau), on the fewest lags over
which S levels off (``noise_structure``).
The simulations then draw AR(1) noise of the same per-sample std and the same T:
ρ = (T − 1) / (T + 1) (a W-sample moving average's noise has T = W; a test pins the read). Solving
an AR(1)'s shape to S instead would assume the shape the area rule does not need, and a moving
average is far from that shape.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numba import njit

from ema.estimate.stats import MAD_TO_STD
from ema.kinds.rotary.simulator.hinge import denoised_hinge_nm
from ema.model import runtime
from ema.model.noise import NOISY_SIGNALS, SensorNoise
from ema.model.params import MAX_CORRELATION_S

# Lags where the window's difference from its clean simulation is still noise: beyond 16 samples the
# loop's timing differences from the model reach the current and speed; the hinge moment is read
# against its own 40 ms reading, and a strain-gauge amplifier correlates its noise for longer.
MAX_LAG = {"position_deg": 16, "motor_speed_radps": 16, "current_a": 16, "hinge_moment_nm": 64}
AREA_PER_COVARIANCE = 7.5  # Σ(6R(0) − S(L)) / ΣR(k): 8 for a lag-1 correlation, 7 for a smooth one
# A correlation shows as a dip of S below its plateau; the mismatch's shallow rise over many lags does not,
# and counted as area it would read white noise as correlated.
DIP = 0.1
# Noise's S is flat past its correlation; the mismatch's grows as L⁴. A span of lags is the noise's when
# S rises by at most ``RISE`` of its plateau across the span's upper half (a least-squares line: a
# correlation longer than the span rises ~0.67 there). The fewest flat lags keep the mismatch's rise out.
RISE = 0.25
MIN_LAGS = 8


def second_difference_variance(values: np.ndarray, lag: int) -> float:
    """S(L): the robust variance of x[k+L] − 2·x[k] + x[k−L]."""
    return second_difference_variances(values, lag, lag)[0]


def second_difference_variances(values: np.ndarray, first_lag: int, last_lag: int) -> list[float]:
    """S(L) for L = first_lag … last_lag: each the ``robust_variance`` of the lag's second difference, equal
    to it to the last bit (the square taken here, as Python takes it: a compiled x·x can differ by one ulp)."""
    mads = _second_difference_mads(np.ascontiguousarray(values, dtype=np.float64), first_lag, last_lag)
    return [(MAD_TO_STD * float(mad)) ** 2 for mad in mads]


@njit(cache=True, nogil=True)
def _second_difference_mads(values, first_lag, last_lag):
    """(last_lag − first_lag + 1,) the median absolute deviation of x[k+L] − 2·x[k] + x[k−L] per lag L,
    ``values`` (n,): the same operations in the same order as NumPy's, compiled (two medians of n samples a
    lag are most of a window's noise reading) and without the GIL."""
    out = np.empty(max(last_lag - first_lag + 1, 0))
    work = np.empty(values.shape[0])
    for i in range(out.shape[0]):
        lag = first_lag + i
        n = values.shape[0] - 2 * lag
        for k in range(n):
            work[k] = values[k + 2 * lag] - 2 * values[k + lag] + values[k]
        middle = np.median(work[:n])
        for k in range(n):
            work[k] = abs(work[k] - middle)
        out[i] = np.median(work[:n])
    return out


def plateau_and_dip(structure: np.ndarray) -> tuple[float, int]:
    """S's plateau (the median of its upper half: 6·R(0)) and how many of the first lags dip below
    ``1 − DIP`` of it (0: white)."""
    plateau = float(np.median(structure[len(structure) // 2 :]))
    reached = np.flatnonzero(structure >= (1.0 - DIP) * plateau)
    return plateau, int(reached[0]) if len(reached) else len(structure)


def levels_off(structure: np.ndarray) -> bool:
    """Whether S over these lags is the noise's: its dip ends in their lower half, and its upper half
    is flat (a least-squares line through it rises by at most ``RISE`` of the plateau)."""
    span, half = len(structure), len(structure) // 2
    plateau, dip = plateau_and_dip(structure)
    lags = np.arange(half, span, dtype=np.float64)
    upper = structure[half:]
    slope = np.sum((lags - lags.mean()) * (upper - upper.mean())) / np.sum((lags - lags.mean()) ** 2)
    return dip <= half and slope * (span - half) <= RISE * plateau


def noise_structure(values: np.ndarray, max_lag: int, rising_is_noise: bool) -> np.ndarray:
    """S(L) for L = 1 … the fewest lags (at least ``MIN_LAGS``: the mismatch grows into the longer
    ones) over which it ``levels_off``, computed lag by lag (white noise's settles at 8). When it never
    does within ``max_lag`` (or the window's half, less 4): all of them if ``rising_is_noise`` (a
    reading against the signal's own smoothing, where the rise is a correlation too long for the
    window), else the first alone, read as white (against a simulation, the rise is the model's
    mismatch: a 1 kHz log's reached the speed's first lags and read 57x its noise's density, and a
    hinge moment 500 N·m off zero made a worn dead band of white speed noise)."""
    available = min(max_lag, (len(values) - 8) // 2)
    values = np.ascontiguousarray(values, dtype=np.float64)
    structure = second_difference_variances(values, 1, min(MIN_LAGS, available))
    while len(structure) < available and not levels_off(np.array(structure)):
        structure.append(second_difference_variance(values, len(structure) + 1))
    if len(structure) >= MIN_LAGS and not rising_is_noise and not levels_off(np.array(structure)):
        return np.array(structure[:1])
    return np.array(structure)


def noise_of(
    difference: np.ndarray, sample_rate_hz: float, max_lag: int, rising_is_noise: bool = False
) -> tuple[float, float]:
    """(σ, τ [s]) of the AR(1) noise with the per-sample variance and the low-frequency density of the
    noise in ``difference`` (measured minus a clean reference of the same window; ``noise_structure``
    says what a difference that never levels off is read as)."""
    structure = noise_structure(difference, max_lag, rising_is_noise)
    if len(structure) == 0:
        return 0.0, 0.0
    plateau, correlated = plateau_and_dip(structure)  # the lags 1 … correlated dip
    if correlated == 0 or plateau <= 0.0:
        return float(np.sqrt(structure[0] / 6.0)), 0.0  # white
    area = float(np.sum(plateau - structure[:correlated]))
    t = 1.0 + 2.0 * area / AREA_PER_COVARIANCE / (plateau / 6.0)
    tau_s = -1.0 / np.log((t - 1.0) / (t + 1.0)) / sample_rate_hz
    return float(np.sqrt(plateau / 6.0)), float(min(tau_s, MAX_CORRELATION_S))


def excess_noise(
    measured: Mapping[str, np.ndarray], clean: Mapping[str, np.ndarray], sample_rate_hz: float
) -> SensorNoise:
    """The noise in ``measured`` beyond the model's own ``clean`` signals of the same window (e.g. PWM
    ripple the model does not draw is counted as noise), with its correlation time.

    The hinge moment is the exception: the simulations feel the *logged* load, so their clean hinge
    moment carries the slow part of its noise; the reference is the window's own denoised reading.
    """
    reference = dict(clean)
    reference["hinge_moment_nm"] = denoised_hinge_nm(
        np.asarray(measured["hinge_moment_nm"]), np.asarray(measured["position_deg"]), sample_rate_hz
    )

    def read(name: str) -> tuple[float, float]:
        difference = np.asarray(measured[name]) - np.asarray(reference[name])
        return noise_of(difference, sample_rate_hz, MAX_LAG[name], rising_is_noise=name == "hinge_moment_nm")

    levels = {}
    for name, (sigma, tau_s) in zip(NOISY_SIGNALS, runtime.map_on_pool(read, NOISY_SIGNALS), strict=True):
        levels[name], levels[f"{name}_corr_s"] = sigma, tau_s
    return SensorNoise(**levels)
