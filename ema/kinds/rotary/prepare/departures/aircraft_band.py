"""The band where the logged hinge moment follows the logged deflection as the aircraft model says:
between 10 and 400 Hz (``BAND_S``), slower than the sensors' noise and faster than the aircraft's own
motion (``ema.kinds.rotary.prepare.departures.aircraft_check`` reads the gauge's gain there,
``ema.kinds.rotary.prepare.alignment`` its lag).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ema.kinds.rotary.evidence import JACKKNIFE_BLOCKS, jackknife_std
from ema.kinds.rotary.physics.noise_reading import MAX_LAG, noise_of
from ema.kinds.rotary.simulator.hinge import local_line
from ema.kinds.rotary.simulator.residual import kernel_samples

BAND_S = (0.0025, 0.1)  # the band compared: slower than the noise, faster than the aircraft's own motion


def band_part(values: np.ndarray, rate: float) -> np.ndarray:
    """``values`` between ``BAND_S``: their local line over the shorter span (``simulator.hinge.local_line``)
    minus that over the longer, i.e. what moves faster than the aircraft and slower than the noise."""
    short, long = (kernel_samples(rate, span) for span in BAND_S)
    return local_line(values, short) - local_line(values, long)


def band_noise_variance(position_deg: np.ndarray, rate: float) -> float:
    """The variance a sample the position sensor's noise keeps in ``band_part``: σ² of its AR(1) reading
    (``ema.kinds.rotary.physics.noise_reading``), over the independent values in the shorter span."""
    sigma, tau_s = noise_of(position_deg, rate, MAX_LAG["position_deg"])
    rho = math.exp(-1.0 / (tau_s * rate)) if tau_s > 0 else 0.0
    span = kernel_samples(rate, BAND_S[0])
    return sigma**2 * min((1.0 + rho) / (1.0 - rho), span) / span


def band_lag_s(signals: Mapping[str, np.ndarray], rate: float, gear_ratio: float) -> tuple[float, float]:
    """How late [s] the logged moment follows the logged deflection in the band, and its std (inf: no fast
    motion to read it by): H_b = K·δ_b − K·L·δ̇_b for a moment L late. δ̇ is the motor's speed over the
    gear ratio (the user side's while the backlash is closed): the position's own derivative carries its
    noise times the rate, and read behind filters 0.6–0.8 of the lag. The std is the larger of a
    jackknife's and white noise's with one independent value per ``span`` samples (as ``slope``)."""
    hinge, position = (band_part(signals[name], rate) for name in ("hinge_moment_nm", "position_deg"))
    turning = band_part(np.degrees(signals["motor_speed_radps"]) / gear_ratio, rate)
    n = len(hinge)
    blocks = np.minimum(np.arange(n) * JACKKNIFE_BLOCKS // n, JACKKNIFE_BLOCKS - 1)
    sums = np.stack(
        [
            np.bincount(blocks, weights=w, minlength=JACKKNIFE_BLOCKS)
            for w in (position * position, position * turning, turning * turning, hinge * position, hinge * turning)
        ]
    )
    every = np.concatenate([sums.sum(axis=1, keepdims=True), sums.sum(axis=1, keepdims=True) - sums], axis=1)
    pp, pt, tt, hp, ht = every
    determinant = pp * tt - pt**2
    with np.errstate(invalid="ignore", divide="ignore"):
        k, c = (hp * tt - ht * pt) / determinant, (ht * pp - hp * pt) / determinant
        lag = -c / k
    if not (np.all(np.isfinite(lag)) and determinant[0] > 0.0):
        return math.nan, math.inf
    residual = hinge - k[0] * position - c[0] * turning
    variance = float(residual @ residual) / n * kernel_samples(rate, BAND_S[0]) / determinant[0]
    # var(c + L·k) / k² with the inverse Gram's entries pp/det, L²·tt/det, −2L·pt/det (δ(−c/k) = −(δc + L·δk)/k)
    white = math.sqrt(max(variance * (pp[0] + lag[0] ** 2 * tt[0] + 2 * lag[0] * pt[0]), 0.0)) / abs(k[0])
    return float(lag[0]), max(white, float(jackknife_std(lag[None, 1:])[0]))
