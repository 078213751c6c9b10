"""Remaining useful life: when a trend crosses its threshold, with an interval, or no degradation.

The trend's (level, slope) is uncertain with the covariance of its fit; drawing from it gives a
distribution of crossing times t* = (threshold − level)/slope, and its 5/50/95 % quantiles are
the RUL and its interval (draws whose slope points away from the threshold never cross: their
t* is infinite, which is what leaves the upper bound open when the data cannot close it). A
degradation is claimed only if the slope points towards the threshold with ≥ 95 % probability.
"""

from __future__ import annotations

import numpy as np

from prognosis.documents import RemainingLife, Trend

DRAWS = 20_000
MIN_PROBABILITY = 0.95
MIN_WINDOWS = 3


def remaining_life(trend: Trend, threshold: float, direction: str, seed: int = 0) -> RemainingLife:
    """RUL of ``trend`` to ``threshold``, crossed going ``direction`` ("above" or "below")."""
    sign = 1.0 if direction == "above" else -1.0
    common = {"parameter": trend.parameter, "threshold": threshold, "direction": direction}
    if trend.n < MIN_WINDOWS:
        return RemainingLife(**common, status="too few windows", rul=None, rul_low=None, rul_high=None,
                             probability_degrading=None)  # fmt: skip
    if sign * (trend.level - threshold) >= 0:
        return RemainingLife(**common, status="already crossed", rul=0.0, rul_low=0.0, rul_high=0.0,
                             probability_degrading=None)  # fmt: skip
    level, slope = _draws(trend, seed)
    towards = sign * slope > 0
    probability = float(np.mean(towards))
    if probability < MIN_PROBABILITY:
        return RemainingLife(**common, status="no degradation detected", rul=None, rul_low=None, rul_high=None,
                             probability_degrading=probability)  # fmt: skip
    crossing = np.maximum(np.where(towards, (threshold - level) / np.where(towards, slope, 1.0), np.inf), 0.0)
    low, median, high = np.quantile(crossing, [0.05, 0.5, 0.95])
    upper = float(high) if np.isfinite(high) else None
    return RemainingLife(**common, status="crossing predicted", rul=float(median), rul_low=float(low),
                         rul_high=upper, probability_degrading=probability)  # fmt: skip


def _draws(trend: Trend, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``DRAWS`` (level, slope) pairs from the trend's fit, correlated as its covariance says: the level is
    quoted at the last window, so a line tilted steeper also ends higher (on 300 synthetic histories drawn
    independently, the 90 % interval held the true life in 81 %)."""
    rng = np.random.default_rng(seed)
    first, second = rng.standard_normal((2, DRAWS))
    rho = trend.level_slope_correlation
    level = trend.level + trend.level_std * first
    slope = trend.slope_per_unit + trend.slope_std * (rho * first + np.sqrt(1.0 - rho**2) * second)
    return level, slope
