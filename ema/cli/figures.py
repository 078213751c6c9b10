"""The PNG figures the commands write: calibration residuals, an actuator's prognosis, bench latency."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def residual_figure(plot: Any, path: Path) -> Path:
    """A calibration's ``ResidualPlot``: each series against the variable that explains it."""
    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(7, 4))
    for series, colour in zip(plot.series, ("tab:red", "tab:blue", "tab:orange", "tab:green"), strict=False):
        axis.scatter(series.x, series.y, s=3, alpha=0.4, color=colour, label=series.label)
    axis.set(xlabel=plot.x_label, ylabel=plot.y_label)
    axis.set_title(plot.title)
    axis.legend(markerscale=4)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)
    return path


def prognosis_figure(prognosis: Any, parameter: str, path: Path, unit: str = "") -> Path:
    """Estimates with ±2 std, the line through them, the weighed laws' forecast (median and 90 % band), the
    threshold and the RUL interval (a constant read beside the health has neither); ``unit``: the parameter's (none
    for an efficiency)."""
    plt = _pyplot()
    trend = prognosis.trends[parameter] if parameter in prognosis.trends else prognosis.constants[parameter]
    life = prognosis.remaining_life.get(parameter)
    t = np.array([p.time for p in trend.points])
    v = np.array([p.value for p in trend.points])
    s = np.array([np.nan if p.std is None else p.std for p in trend.points])
    outlier = np.array([p.outlier for p in trend.points])
    figure, axis = plt.subplots(figsize=(8, 4.5))
    axis.errorbar(t[~outlier], v[~outlier], yerr=2 * s[~outlier], fmt="o", ms=3, lw=0.8, label="estimates ± 2 std")
    if outlier.any():
        axis.plot(t[outlier], v[outlier], "x", color="tab:gray", label="outliers (down-weighted)")
    horizon = 0.0 if life is None else life.rul_high if life.rul_high is not None else 1.5 * (life.rul or 0.0)
    grid = np.linspace(t.min(), t.max() + horizon, 200)
    axis.plot(grid, trend.level + trend.slope_per_unit * (grid - t.max()), color="tab:gray", lw=0.8, label="line")
    if trend.forecast:
        _forecast(axis, trend)
    if life is not None:
        _life(axis, life, t.max(), grid[-1])
    status = "read beside the health: no failure level" if life is None else prognosis.life_status(parameter)
    axis.set(
        xlabel=prognosis.time_unit.replace("_", " "),
        ylabel=f"{parameter} [{unit}]" if unit else parameter,
        title=f"{prognosis.actuator_id}: {parameter}\n{status}",
    )
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)
    return path


def _forecast(axis: Any, trend: Any) -> None:
    """The weighed laws' forecast: its median and its 90 % band."""
    at = np.array([p.time for p in trend.forecast])
    laws = ", ".join(f"{k} {w:.2f}" for k, w in sorted(trend.laws.items(), key=lambda x: -x[1]) if w >= 0.1)
    axis.plot(at, [p.median for p in trend.forecast], color="tab:orange", label=f"forecast ({laws})")
    axis.fill_between(
        at,
        [p.low for p in trend.forecast],
        [p.high for p in trend.forecast],
        color="tab:orange",
        alpha=0.2,
        label="forecast 90 % band",
    )


def _life(axis: Any, life: Any, last: float, end: float) -> None:
    """The failure level and the remaining life's 90 % interval from the last window (``last``) on."""
    axis.axhline(life.threshold, color="tab:red", ls="--", label=f"threshold ({life.direction})")
    if life.rul_low is not None:
        high = last + (life.rul_high if life.rul_high is not None else end - last)
        axis.axvspan(last + life.rul_low, high, color="tab:red", alpha=0.1, label="RUL 90 % interval")
