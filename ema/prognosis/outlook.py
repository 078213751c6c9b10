"""One parameter's outlook: its trend, the laws weighed on its history, the forecast and the remaining life.

The windows enter the laws with the weights the trend's robust curve gives them (``ema.prognosis.trend``:
each window's std, the scatter beyond the stds, a Huber weight for a window the model could not
explain), read off the quadratic, which bends with wear that speeds up and so does not take the bend
for scatter as a line would.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ema.estimate.least_squares import weighted
from ema.prognosis.documents import BacktestPoint, ForecastPoint, RemainingLife, Trend
from ema.prognosis.forecast import Forecast, forecast
from ema.prognosis.laws import LAWS, law_curve
from ema.prognosis.rul import MIN_TREND_WINDOWS, remaining_life
from ema.prognosis.trend import HUBER_C, Series, excess_variance, robust_polynomial, trend_of
from ema.prognosis.weigh import MIN_LAW_WINDOWS, weigh

BAND_POINTS = 40  # forecast points reported, from the first window to the crossing (or 3 spans past the last)
LATE_SHARE = 1.0 / 3.0  # the latest windows whose slope is set against the whole history's
MIN_LATE = 5
SPEEDING_Z = 2.0
ROBUST_PASSES = 3


@dataclass(frozen=True)
class Outlook:
    trend: Trend
    life: RemainingLife
    backtest: list[BacktestPoint] = field(default_factory=list)


def law_inputs(times: np.ndarray, values: np.ndarray, stds: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(s, weight, t_first, span): times on [0, 1] and each window's weight h / (σ² + τ²), the Huber weight h
    and τ² read off the law and shape that explain the windows best: scatter beyond the stds is read as such
    only where no law follows it, and a line's misfit to wear that speeds up does not down-weigh the latest
    windows, which tell most of where it goes."""
    known = np.isfinite(stds) & (stds > 0)
    variance = np.where(known, stds, np.median(stds[known]) if known.any() else 0.0) ** 2
    t_first, span = float(times.min()), float(np.ptp(times))
    s = (times - t_first) / span
    curve = robust_polynomial(s - 1.0, values, variance, 1)
    robust, tau2 = curve["robust"], float(curve["tau2"])
    if len(times) < MIN_LAW_WINDOWS:
        return s, robust / (variance + tau2 + 1e-300), t_first, span
    robust = np.ones(len(s))
    for _ in range(ROBUST_PASSES):  # the best law's residuals set τ and the Huber weights, and again
        weight = robust / (variance + tau2 + 1e-300)
        best = max((law_curve(law, s, values, weight) for law in LAWS), key=lambda f: f.log_likelihood)
        shape = int(np.argmax(best.weights))
        residual = values - best.law.columns(s, best.law.shapes[shape]) @ best.betas[shape]
        tau2 = excess_variance(residual, variance, robust, max(int(robust.sum()) - len(best.betas[shape]), 1))
        robust = np.minimum(1.0, HUBER_C / np.maximum(np.abs(residual) / np.sqrt(variance + tau2 + 1e-300), 1e-12))
    return s, robust / (variance + tau2 + 1e-300), t_first, span


def speeding_up(times: np.ndarray, values: np.ndarray, weight: np.ndarray, sign: float) -> bool:
    """Whether the latest windows' slope exceeds the whole history's towards the threshold by ``SPEEDING_Z``."""
    late = np.argsort(times)[-max(MIN_LATE, int(LATE_SHARE * len(times))) :]
    if len(late) >= len(times) or np.ptp(times[late]) <= 0:
        return False
    slopes = [_slope(times[rows], values[rows], weight[rows]) for rows in (late, np.arange(len(times)))]
    (late_slope, late_var), (all_slope, all_var) = slopes
    return bool(sign * (late_slope - all_slope) > SPEEDING_Z * np.sqrt(late_var + all_var))


def _slope(t: np.ndarray, y: np.ndarray, w: np.ndarray) -> tuple[float, float]:
    beta, covariance, _ = weighted(np.column_stack([np.ones_like(t), t - t.mean()]), y, w)
    return float(beta[1]), float(covariance[1, 1])


def band(fc: Forecast, life: RemainingLife, span: float) -> list[ForecastPoint]:
    """The forecast's median and 90 % band at ``BAND_POINTS`` times from the last window to the crossing's
    upper bound (or half again its median; at least a fifth of the history's span)."""
    reach = life.rul_high if life.rul_high is not None else (life.rul or 0.0) * 1.5
    end = 1.0 + min(max(reach / span if span > 0 else 0.0, 0.2), fc.s_future[-1] - 1.0)
    s = np.linspace(1.0, end, BAND_POINTS)
    values = np.array([np.interp(s, fc.s_future, curve) for curve in fc.curves[:: max(1, len(fc.curves) // 500)]])
    low, median, high = np.quantile(values, [0.05, 0.5, 0.95], axis=0)
    return [
        ForecastPoint(time=float(fc.times(np.array([x]))[0]), median=m, low=lo, high=hi)
        for x, m, lo, hi in zip(s, median, low, high, strict=True)
    ]


def outlook(series: Series, *, threshold: float, direction: str, min_span: float = 0.0) -> Outlook:
    """The trend and remaining life of one parameter's history (times in the prognosis's unit); no forecast
    where fewer than ``MIN_TREND_WINDOWS`` windows, or windows spanning less than ``min_span``, read it."""
    parameter, times, values, stds = series.parameter, series.times, series.values, series.stds
    trend = trend_of(series)
    if trend.n < MIN_TREND_WINDOWS:
        return Outlook(trend, remaining_life(parameter, None, threshold, direction))
    if trend.slope_std is None or float(np.ptp(times)) < min_span:  # no slope: every window at one time
        return Outlook(trend, remaining_life(parameter, None, threshold, direction, span_too_short=True))
    s, weight, t_first, span = law_inputs(times, values, stds)
    weighed = weigh(s, values, weight)
    fc = forecast(weighed, t_first, span)
    sign = 1.0 if direction == "above" else -1.0
    line = 0.5 * (1.0 + math.erf(sign * trend.slope_per_unit / (trend.slope_std * math.sqrt(2.0))))
    life = remaining_life(parameter, fc, threshold, direction, speeding_up(times, values, weight, sign), line)
    laws = {curve.law.name: float(w) for curve, w in zip(weighed.curves, weighed.weights, strict=True)}
    return Outlook(trend.model_copy(update={"laws": laws, "forecast": band(fc, life, span)}), life)
