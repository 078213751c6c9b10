"""The PNG figures the commands write: calibration residuals, an actuator's prognosis, bench latency."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

LABELS = {
    "speed_radps": "motor speed |ω| [rad/s]",
    "current_a": "current · sgn(ω) [A]",
    "time_s": "time in the window [s]",
    "position_rad": "elevator position [rad]",
    "motor_angle_rad": "motor angle mod 2π [rad]",
    "direction": "direction of motion",
    "load_nm": "load at the shaft, + aiding [N·m]",
}


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def calibration_figure(calibrator: Any, path: Path) -> Path:
    """The equation-error residual before and after, against the variable that explains it."""
    from ema.calibration.fitting import score
    from ema.calibration.selection import problem

    plt = _pyplot()
    e, report = calibrator.measured_, calibrator.report_
    chosen = calibrator.chosen_
    variable = "time_s"
    if chosen:
        variable = chosen[0].family.follows
    elif report.unexplained is not None:
        variable = report.unexplained.variables[0]
    x = e.variables[variable]
    if variable == "motor_angle_rad":
        x = np.mod(x, 2 * np.pi)
    figure, axis = plt.subplots(figsize=(7, 4))
    for label, model, colour in (("before", [], "tab:red"), ("after", chosen, "tab:blue")):
        design, target = problem(e, model)
        residual = target - design @ score(design, target, e.folds).beta
        axis.scatter(x[::4], residual[::4], s=3, alpha=0.4, color=colour, label=label)
    axis.set(xlabel=LABELS.get(variable, variable), ylabel="equation error of Eq. 5.1 [N·m]")
    axis.set_title(f"calibration: {report.selected_effect or 'no effect named'}")
    axis.legend(markerscale=4)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)
    return path


def prognosis_figure(prognosis: Any, parameter: str, path: Path) -> Path:
    """Estimates with ±2 std, the line through them, the weighed laws' forecast (median and 90 % band), the
    threshold and the RUL interval."""
    plt = _pyplot()
    trend, life = prognosis.trends[parameter], prognosis.remaining_life[parameter]
    t = np.array([p.time for p in trend.points])
    v = np.array([p.value for p in trend.points])
    s = np.array([np.nan if p.std is None else p.std for p in trend.points])
    outlier = np.array([p.outlier for p in trend.points])
    figure, axis = plt.subplots(figsize=(8, 4.5))
    axis.errorbar(t[~outlier], v[~outlier], yerr=2 * s[~outlier], fmt="o", ms=3, lw=0.8, label="estimates ± 2 std")
    if outlier.any():
        axis.plot(t[outlier], v[outlier], "x", color="tab:gray", label="outliers (down-weighted)")
    horizon = life.rul_high if life.rul_high is not None else 1.5 * (life.rul or 0.0)
    grid = np.linspace(t.min(), t.max() + horizon, 200)
    axis.plot(grid, trend.level + trend.slope_per_unit * (grid - t.max()), color="tab:gray", lw=0.8, label="line")
    if trend.forecast:
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
    axis.axhline(life.threshold, color="tab:red", ls="--", label=f"threshold ({life.direction})")
    if life.rul_low is not None:
        high = t.max() + (life.rul_high if life.rul_high is not None else grid[-1] - t.max())
        axis.axvspan(t.max() + life.rul_low, high, color="tab:red", alpha=0.1, label="RUL 90 % interval")
    axis.set(
        xlabel=prognosis.time_unit.replace("_", " "),
        ylabel=parameter,
        title=f"{prognosis.actuator_id}: {parameter}: {life.status}",
    )
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)
    return path
