"""Remaining useful life: when a parameter's forecast crosses its threshold, with an interval, or no degradation.

The forecast's curves (``ema.prognosis.forecast``: every law in the share of its weight) each cross the
threshold once or never; their crossing times' 5/50/95 % quantiles are the RUL and its interval
(curves that never get there within the horizon cross at infinity, which leaves the upper bound open
when the data cannot close it). A degradation is claimed only where the curves move towards the
threshold at the last window with ≥ 95 % probability, and the whole history's line with ≥ 99 %. The
earliest plausible crossing is the 5 % quantile of the law that crosses soonest among those that hold
some weight: the date to plan for if the wear is of that kind.
"""

from __future__ import annotations

import numpy as np

from ema.prognosis.documents import RemainingLife
from ema.prognosis.forecast import PLAUSIBLE_WEIGHT, Forecast

MIN_PROBABILITY = 0.95
MIN_LINE_PROBABILITY = 0.99  # the whole history's line towards the threshold (at 0.95 a steady one passes by chance
# one time in twenty)
MIN_TREND_WINDOWS = 3  # fewer: no trend, and no forecast ("too few windows")


def remaining_life(
    parameter: str,
    forecast: Forecast | None,
    threshold: float,
    direction: str,
    speeding_up: bool = False,
    line_probability: float = 1.0,
    *,
    span_too_short: bool = False,
) -> RemainingLife:
    """RUL of ``parameter`` to ``threshold``, crossed going ``direction`` ("above" or "below"); ``forecast``
    None where the history holds too few windows (or all at one time) to say where it goes;
    ``line_probability``: how likely the whole history's line moves towards the threshold. A degradation
    is claimed where both the curves at the last window and that line say so: a law that bends with a
    steady history's last few windows does not raise an alarm alone."""
    sign = 1.0 if direction == "above" else -1.0
    common = {"parameter": parameter, "threshold": threshold, "direction": direction, "speeding_up": speeding_up}
    none = {"rul": None, "rul_low": None, "rul_high": None, "rul_earliest": None}
    if forecast is None:
        status = "span too short" if span_too_short else "too few windows"
        return RemainingLife(**common, status=status, **none, probability_degrading=None)
    if sign * (float(np.median(forecast.curves[:, 0])) - threshold) >= 0:
        return RemainingLife(
            **common,
            status="already crossed",
            rul=0.0,
            rul_low=0.0,
            rul_high=0.0,
            rul_earliest=0.0,
            probability_degrading=None,
        )
    probability = float(np.mean(sign * forecast.slope_now() > 0))
    if probability < MIN_PROBABILITY or line_probability < MIN_LINE_PROBABILITY:
        return RemainingLife(**common, status="no degradation detected", **none, probability_degrading=probability)
    crossing = forecast.crossing(threshold, sign)
    with np.errstate(invalid="ignore"):  # curves that never cross, at infinity: a quantile among them is inf
        low, median, high = np.quantile(crossing, [0.05, 0.5, 0.95], method="inverted_cdf")
    return RemainingLife(
        **common,
        status="crossing predicted",
        rul=float(median),
        rul_low=float(low),
        rul_high=float(high) if np.isfinite(high) else None,
        rul_earliest=earliest(forecast, crossing),
        probability_degrading=probability,
    )


def earliest(forecast: Forecast, crossing: np.ndarray) -> float:
    """The 5 % quantile of the crossings of the law that crosses soonest among those weighing
    ``PLAUSIBLE_WEIGHT`` or more."""
    quantiles = [
        float(np.quantile(crossing[forecast.law_of_curve == index], 0.05, method="inverted_cdf"))
        for index, weight in enumerate(forecast.weights)
        if weight >= PLAUSIBLE_WEIGHT and np.any(forecast.law_of_curve == index)
    ]
    return min(quantiles)
