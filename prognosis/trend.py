"""A parameter's trend over an actuator's windows: weighted by each window's std, robust to outliers.

value_i = level + slope·(t_i − t_last) + e_i, e_i ~ N(0, σ_i² + τ²). σ_i is the std the pipeline
stated; τ, the scatter beyond it, is solved for so that the weighted residuals have unit variance
(a window set whose stds are too small widens the trend's uncertainty instead of narrowing it),
and a Huber weight (c = 2.5) keeps a window the model could not explain from pulling the line.
The level is quoted at the last window, where it is best known and where the remaining life starts.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from prognosis.documents import Point, Trend

HUBER_C = 2.5
OUTLIER_Z = 3.5
ITERATIONS = 20


def _wls(x: np.ndarray, y: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(coefficients (level, slope), covariance) of weighted least squares with weights w = 1/variance."""
    design = np.column_stack([np.ones_like(x), x])
    gram = design.T @ (w[:, None] * design)
    covariance = np.linalg.pinv(gram)
    return covariance @ design.T @ (w * y), covariance


def _excess_variance(residual: np.ndarray, variance: np.ndarray, robust: np.ndarray, dof: int) -> float:
    """τ² ≥ 0 with Σ h·r²/(σ² + τ²) = Σ h − 2 (bisection; 0 when the stds already explain the scatter)."""

    def excess(tau2: float) -> float:
        return float(np.sum(robust * residual**2 / (variance + tau2)) - dof)

    if excess(0.0) <= 0:
        return 0.0
    low, high = 0.0, float(np.max(residual**2)) + 1e-30
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if excess(mid) > 0 else (low, mid)
    return 0.5 * (low + high)


def fit_trend(
    parameter: str, times: np.ndarray, values: np.ndarray, stds: np.ndarray, window_ids: Sequence[str]
) -> Trend:
    """The trend of one parameter (times in the prognosis's unit; stds may hold NaN for "unknown")."""
    x = times - times.max()
    known = np.isfinite(stds) & (stds > 0)
    variance = np.where(known, stds, np.median(stds[known]) if known.any() else 0.0) ** 2
    robust, tau2 = np.ones(len(x)), 0.0
    for _ in range(ITERATIONS):
        beta, covariance = _wls(x, values, robust / (variance + tau2 + 1e-300))
        residual = values - beta[0] - beta[1] * x
        tau2 = _excess_variance(residual, variance, robust, max(int(robust.sum()) - 2, 1)) if len(x) > 2 else 0.0
        z = np.abs(residual) / np.sqrt(variance + tau2 + 1e-300)
        robust = np.minimum(1.0, HUBER_C / np.maximum(z, 1e-12))
    points = [
        Point(window_id=w, time=float(t), value=float(v), std=float(s) if k else None, outlier=bool(zz > OUTLIER_Z))
        for w, t, v, s, k, zz in zip(window_ids, times, values, stds, known, z, strict=True)
    ]
    return Trend(
        parameter=parameter,
        n=len(x),
        level=float(beta[0]),
        level_std=float(np.sqrt(covariance[0, 0])),
        slope_per_unit=float(beta[1]),
        slope_std=float(np.sqrt(covariance[1, 1])),
        level_slope_correlation=float(np.clip(covariance[0, 1] / np.sqrt(covariance[0, 0] * covariance[1, 1]), -1, 1)),
        excess_std=float(np.sqrt(tau2)),
        points=points,
    )
