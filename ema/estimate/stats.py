"""Statistics every stage shares: block-jackknife stds, likelihood ratios of two solutions, posterior weights of two
stories, and how decisive a difference must be."""

from __future__ import annotations

import numpy as np

DECISIVE_Z = 4.0  # stds by which a reading must explain a window better than the document's before it is taken
MAX_RATIO = 2.0  # every kind's check: an output error within twice its noise floor is reproduced
SIGN_STDS = 3.0  # a constant that must be positive read this many stds below zero: the log's signs, not its noise
# The share of the drive's effort (the motor torque k_T·I, a servo's force) under which a model's error is no
# evidence: the document's k_T alone moves 0.1 %/K with the magnets' temperature, and ema's integration of a closed
# loop leaves 0.1 % of the force against an exact solution. Equation and output errors are read against a noise
# never under it, so a log without sensor noise is judged as one with a little, never as an exact model's.
RESOLUTION_SHARE = 0.002


def odds_weight(log_odds: float) -> float:
    """The posterior weight of a story whose ln posterior odds against its rival are ``log_odds`` (clipped
    where exp would overflow)."""
    return float(1.0 / (1.0 + np.exp(-np.clip(log_odds, -50.0, 50.0))))


def rms(values: np.ndarray) -> float:
    """The root mean square of ``values`` (0 for none)."""
    return float(np.sqrt(np.mean(values**2))) if len(values) else 0.0


def below_zero(values: dict[str, float], stds: dict[str, float]) -> list[str]:
    """The names whose value lies more than ``SIGN_STDS`` stds below zero: of constants that must be positive (a
    mass, a friction that opposes the motion), what no noise explains, and a log's sign or time reversed does."""
    return [name for name in values if values[name] < -SIGN_STDS * stds[name]]


MAD_TO_STD = 1.4826  # σ of Gaussian data over its median absolute deviation


def robust_variance(values: np.ndarray) -> float:
    """(1.4826 · MAD)²: the variance of Gaussian data, unmoved by a few outliers."""
    mad = np.median(np.abs(values - np.median(values)))
    return float((MAD_TO_STD * mad) ** 2)


def white_noise_std(values: np.ndarray) -> float:
    """Robust std of white noise on a smooth signal: √(robust variance of the second difference / 6).

    Δ²x of white noise has variance 6σ²; the smooth signal contributes little to it at 10 kHz, and
    the median ignores the few samples where the motion itself turns sharply.
    """
    return float(np.sqrt(robust_variance(np.diff(values, n=2)) / 6.0))
