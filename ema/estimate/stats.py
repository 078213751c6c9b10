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


def between_runs_std(values: np.ndarray, stds: np.ndarray, centre: float | None = None) -> float:
    """τ ≥ 0, how far readings of one quantity scatter beyond their stated ``stds``: Paule and Mandel's root of
    Σ (v − m)² / (σ² + τ²) = n − 1 about their inverse-variance mean m, or = n about a known ``centre`` (a nominal the
    readings are judged against, so that their offset from it is part of their scatter); 0 where the stds explain it.

    Each reading is weighed by its own std, so a precise reading that lies off counts as such: the spread less the
    mean stated variance lets a few imprecise readings hide the precise ones' scatter."""
    n = len(values)
    if n < (1 if centre is not None else 3):
        return 0.0

    def excess(tau2: float) -> float:
        weights = 1.0 / np.maximum(stds**2 + tau2, 1e-300)
        mean = float(np.sum(weights * values) / np.sum(weights)) if centre is None else centre
        return float(np.sum(weights * (values - mean) ** 2)) - (n - 1 if centre is None else n)

    if excess(0.0) <= 0:
        return 0.0
    # where the excess is ≤ 0 (every term under 1 about a known centre), bisected
    high = float(np.var(values)) * 10 if centre is None else float(np.max((values - centre) ** 2))
    low, high = 0.0, high + 1e-18
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if excess(mid) > 0 else (low, mid)
    return float(np.sqrt(0.5 * (low + high)))
