"""How far to trust a prognosis on this actuator: the prognosis as it would have stood at earlier windows,
against what came after.

At several earlier windows (``SHARES`` of the history) the outlook is computed from the windows up to there
alone (``ema.prognosis.outlook``). Each such point says what was predicted then (the remaining life, and the
crossing date it implies) and how the windows since fell against the forecast made then: the share of them
inside its 90 % band (widened by each window's own std). A prognosis whose past forecasts held its later
windows, and whose crossing dates agree from one point to the next, can be trusted here; one whose
crossing dates keep moving in, less.
"""

from __future__ import annotations

import numpy as np

from ema.prognosis.documents import BacktestPoint, ForecastPoint
from ema.prognosis.outlook import outlook
from ema.prognosis.rul import MIN_TREND_WINDOWS
from ema.prognosis.trend import Series

SHARES = (0.5, 0.65, 0.8)
Z_90 = 1.645


def backtest(series: Series, *, threshold: float, direction: str, min_span: float = 0.0) -> list[BacktestPoint]:
    """The prognosis at ``SHARES`` of the history (in time order), each against the windows after it."""
    series = series.in_time_order()
    times, values, stds, ids = series.times, series.values, series.stds, series.window_ids
    points = []
    for share in SHARES:
        k = round(share * len(times))
        if k < MIN_TREND_WINDOWS or k >= len(times) or np.ptp(times[:k]) <= 0:
            continue
        then = outlook(series.first(k), threshold=threshold, direction=direction, min_span=min_span)
        life = then.life
        inside = _inside(then.trend.forecast, times[k:], values[k:], stds[k:])
        points.append(
            BacktestPoint(
                window_id=ids[k - 1],
                time=float(times[k - 1]),
                windows=k,
                status=life.status,
                rul=life.rul,
                rul_low=life.rul_low,
                rul_high=life.rul_high,
                crossing=None if life.rul is None else float(times[k - 1] + life.rul),
                later_windows=len(times) - k,
                later_inside=inside,
            )
        )
    return points


def _inside(band: list[ForecastPoint], times: np.ndarray, values: np.ndarray, stds: np.ndarray) -> float | None:
    """The share of later windows within the band (widened by their own std), of those the band reaches."""
    if not band:
        return None
    t = np.array([p.time for p in band])
    reached = times <= t[-1]
    if not reached.any():
        return None
    noise = Z_90 * np.where(np.isfinite(stds), stds, 0.0)[reached]
    low = np.interp(times[reached], t, [p.low for p in band]) - noise
    high = np.interp(times[reached], t, [p.high for p in band]) + noise
    return float(np.mean((values[reached] >= low) & (values[reached] <= high)))
