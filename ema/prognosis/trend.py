"""A parameter's trend over an actuator's windows: weighted by each window's std, robust to outliers.

value_i = level + slope·(t_i − t_last) + e_i, e_i ~ N(0, σ_i² + τ²). σ_i is the std the pipeline
stated; τ, the scatter beyond it, is solved for so that the weighted residuals have unit variance
(a window set whose stds are too small widens the trend's uncertainty instead of narrowing it),
and a Huber weight (c = 2.5) keeps a window the model could not explain from pulling the line.
The level is quoted at the last window, where it is best known and where the remaining life starts.

Wear need not be linear: friction that grows faster as the transmission wears bends the windows
upwards, and a line through them would cross its threshold far too late, and surely. So the
quadratic is drawn beside the line (the same weights, its own τ) and weighed against it by BIC with
the quadratic's scatter: ln odds = ½(χ²_line − χ²_curve) − ½ ln n, which says whether the history
bends. Which law to extrapolate is ``ema.prognosis.weigh``'s question.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ema.estimate.least_squares import weighted
from ema.estimate.stats import odds_weight
from ema.prognosis.documents import Curved, Point, Trend

HUBER_C = 2.5
OUTLIER_Z = 3.5
HUBER_ITERATIONS = 20
MIN_CURVED = 6  # windows from which a quadratic is drawn beside the line


def _wls(x: np.ndarray, y: np.ndarray, w: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """(coefficients (level, slope[, curvature]), covariance) of weighted least squares, w = 1/variance."""
    beta, covariance, _ = weighted(np.vander(x, degree + 1, increasing=True), y, w)
    return beta, covariance


def excess_variance(residual: np.ndarray, variance: np.ndarray, robust: np.ndarray, dof: int) -> float:
    """τ² ≥ 0 with Σ h·r²/(σ² + τ²) = Σ h − p (bisection; 0 when the stds already explain the scatter)."""

    def excess(tau2: float) -> float:
        return float(np.sum(robust * residual**2 / (variance + tau2)) - dof)

    if excess(0.0) <= 0:
        return 0.0
    low, high = 0.0, float(np.max(residual**2)) + 1e-30
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if excess(mid) > 0 else (low, mid)
    return 0.5 * (low + high)


def robust_polynomial(x: np.ndarray, values: np.ndarray, variance: np.ndarray, degree: int) -> dict[str, np.ndarray]:
    """The polynomial of ``degree`` in x by iteratively reweighted least squares (τ and Huber weights)."""
    n_coefficients = degree + 1
    robust, tau2 = np.ones(len(x)), 0.0
    for _ in range(HUBER_ITERATIONS):
        beta, covariance = _wls(x, values, robust / (variance + tau2 + 1e-300), degree)
        residual = values - np.vander(x, n_coefficients, increasing=True) @ beta
        dof = max(int(robust.sum()) - n_coefficients, 1)
        tau2 = excess_variance(residual, variance, robust, dof) if len(x) > n_coefficients else 0.0
        z = np.abs(residual) / np.sqrt(variance + tau2 + 1e-300)
        robust = np.minimum(1.0, HUBER_C / np.maximum(z, 1e-12))
    return {
        "beta": beta,
        "covariance": covariance,
        "tau2": np.float64(tau2),
        "z": z,
        "robust": robust,
        "residual": residual,
    }


def curved(x: np.ndarray, values: np.ndarray, variance: np.ndarray, line: dict[str, np.ndarray]) -> Curved | None:
    """The quadratic beside ``line`` and its BIC weight, both read with the quadratic's scatter and weights."""
    if len(x) < MIN_CURVED:
        return None
    curve = robust_polynomial(x, values, variance, 2)
    scale = variance + curve["tau2"]
    chi2 = [float(np.sum(curve["robust"] * curve["residual"] ** 2 / scale)) for curve in (line, curve)]
    log_odds = 0.5 * (chi2[0] - chi2[1]) - 0.5 * np.log(max(float(curve["robust"].sum()), 2.0))
    beta, covariance = curve["beta"], curve["covariance"]
    return Curved(
        level=float(beta[0]),
        slope_per_unit=float(beta[1]),
        curvature_per_unit2=float(beta[2]),
        covariance=covariance.tolist(),
        weight=odds_weight(float(log_odds)),
    )


@dataclass(frozen=True)
class Series:
    """One parameter's readings, window by window: what a trend, an outlook and a backtest read (times in the
    prognosis's unit; stds may hold NaN for "unknown")."""

    parameter: str
    times: np.ndarray
    values: np.ndarray
    stds: np.ndarray
    window_ids: Sequence[str]

    def in_time_order(self) -> Series:
        order = np.argsort(self.times, kind="stable")
        ids = [self.window_ids[i] for i in order]
        return Series(self.parameter, self.times[order], self.values[order], self.stds[order], ids)

    def first(self, k: int) -> Series:
        """The first ``k`` readings."""
        return Series(self.parameter, self.times[:k], self.values[:k], self.stds[:k], self.window_ids[:k])


def trend_of(series: Series) -> Trend:
    """The trend of one parameter's ``series``."""
    times, values, stds = series.times, series.values, series.stds
    x = times - times.max()
    known = np.isfinite(stds) & (stds > 0)
    variance = np.where(known, stds, np.median(stds[known]) if known.any() else 0.0) ** 2
    spans_time = len(np.unique(x)) > 1
    line = robust_polynomial(x, values, variance, 1 if spans_time else 0)
    beta, covariance, z = line["beta"], line["covariance"], line["z"]
    points = [
        Point(window_id=w, time=float(t), value=float(v), std=float(s) if k else None, outlier=bool(zz > OUTLIER_Z))
        for w, t, v, s, k, zz in zip(series.window_ids, times, values, stds, known, z, strict=True)
    ]
    level = {"parameter": series.parameter, "n": len(x), "level": float(beta[0]), "points": points}
    level |= {"level_std": float(np.sqrt(covariance[0, 0])), "excess_std": float(np.sqrt(line["tau2"]))}
    if not spans_time:  # one time holds no slope: the level alone, said so by a null slope_std
        return Trend(**level, slope_per_unit=0.0, slope_std=None)
    return Trend(
        **level,
        slope_per_unit=float(beta[1]),
        slope_std=float(np.sqrt(covariance[1, 1])),
        level_slope_correlation=float(np.clip(covariance[0, 1] / np.sqrt(covariance[0, 0] * covariance[1, 1]), -1, 1)),
        curved=curved(x, values, variance, line),
    )
