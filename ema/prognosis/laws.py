"""Degradation laws a parameter's history may follow, each solved by weighted least squares.

Time is put on s = (t − t_first) / span, 0 at the first window and 1 at the last, so that every law's
columns are of order one. A law is its columns φ(s; θ): linear in its coefficients β for a fixed shape θ,
its shapes a grid over which the curve keeps a posterior (``LawCurve``):

- ``linear``: 1, s;
- ``quadratic``: 1, s, s²;
- ``exponential``: 1, exp(k·s) − 1 for k in ±0.5 … 8 (wear that feeds on itself, or settles);
- ``power``: 1, s^p for p in 1.5 … 5 (a crack, a spall that grows as a power of the hours);
- ``knee``: 1, s, w·ln(1 + exp((s − s_k)/w)) for s_k in 0.1 … 0.95 and w in 0.005 … 0.2 (steady, then a new
  mechanism sets in, sharply or over a while: a softened broken line).

Each window i weighs h_i / (σ_i² + τ²): its stated std, the history's scatter beyond it (τ, read once for
all laws) and its Huber weight h (``ema.prognosis.trend``), so a window the model could not explain does not
bend every law towards it. Within a law, the shapes are weighed by their likelihood with BIC's penalty;
which law to believe is ``ema.prognosis.weigh``'s question.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ema.estimate.least_squares import weighted

# Shapes on grids fine enough that a precise history's posterior does not sit on a neighbour of the truth (on
# a grid of 4 and 6, histories doubling every 4.6 spans read 4, and crossed 6-20 % late).
EXPONENTIAL_RATES = (-4.0, -3.0, -2.0, -1.5, -1.0, -0.5, *np.round(np.arange(0.25, 10.01, 0.25), 2))
POWERS = tuple(np.round(np.arange(1.25, 6.01, 0.25), 2))
KNEES = tuple((float(k), w) for k in np.round(np.arange(0.1, 0.951, 0.05), 2) for w in (0.005, 0.02, 0.05, 0.1, 0.2))


@dataclass(frozen=True)
class Law:
    """A family of curves: its columns at times ``s`` for one shape ``theta``, and the shapes it tries."""

    name: str
    columns: Callable[[np.ndarray, Any], np.ndarray]  # (s, shape) -> (len(s), p)
    shapes: tuple[Any, ...] = (0.0,)


def _exponential(s: np.ndarray, k: float) -> np.ndarray:
    return np.column_stack([np.ones_like(s), np.expm1(k * s) / k])


LAWS = (
    Law("linear", lambda s, _: np.column_stack([np.ones_like(s), s])),
    Law("quadratic", lambda s, _: np.column_stack([np.ones_like(s), s, s**2])),
    Law("exponential", _exponential, EXPONENTIAL_RATES),
    Law("power", lambda s, p: np.column_stack([np.ones_like(s), np.maximum(s, 0.0) ** p]), POWERS),
    Law(
        "knee",
        lambda s, kw: np.column_stack([np.ones_like(s), s, kw[1] * np.logaddexp(0.0, (s - kw[0]) / kw[1])]),
        KNEES,
    ),
)
BY_NAME = {law.name: law for law in LAWS}


@dataclass(frozen=True)
class LawCurve:
    """One law's curve: per shape its posterior weight, coefficients and their covariance."""

    law: Law
    weights: np.ndarray  # (shapes,) posterior over the law's shapes
    betas: list[np.ndarray]  # per shape, (p,)
    covariances: list[np.ndarray]  # per shape, (p, p)
    log_likelihood: float  # the best shape's, with BIC's penalty: how well the law follows what it saw

    def predictive(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mean, variance) of the curve at ``s``: the shapes' mixture (the windows' own noise not included)."""
        means, variances = [], []
        for theta, beta, covariance in zip(self.law.shapes, self.betas, self.covariances, strict=True):
            phi = self.law.columns(s, theta)
            means.append(phi @ beta)
            variances.append(np.einsum("ij,jk,ik->i", phi, covariance, phi))
        mean = np.tensordot(self.weights, np.array(means), axes=1)
        spread = np.tensordot(self.weights, np.array(variances) + (np.array(means) - mean) ** 2, axes=1)
        return mean, spread

    def curves(self, s: np.ndarray, n: int, rng: np.random.Generator, scale: float = 1.0) -> np.ndarray:
        """(n, len(s)) curves drawn from this posterior: a shape by its weight, then coefficients about it, their
        spread ``scale`` times the curve's."""
        shape = rng.choice(len(self.weights), size=n, p=self.weights)
        out = np.empty((n, len(s)))
        for k in np.unique(shape):
            rows = shape == k
            covariance = scale**2 * self.covariances[k]
            beta = rng.multivariate_normal(self.betas[k], covariance, int(rows.sum()), check_valid="ignore")
            out[rows] = beta @ self.law.columns(s, self.law.shapes[k]).T
        return out


def law_curve(law: Law, s: np.ndarray, y: np.ndarray, weight: np.ndarray) -> LawCurve:
    """``law`` drawn through ``y`` at ``s`` with per-window weights h / (σ² + τ²); each shape by BIC's likelihood."""
    betas, covariances, scores = [], [], []
    n_eff = max(float(np.sum(weight > 0)), 2.0)
    for theta in law.shapes:
        phi = law.columns(s, theta)
        beta, covariance, chi2 = weighted(phi, y, weight)
        betas.append(beta)
        covariances.append(covariance)
        scores.append(-0.5 * chi2 - 0.5 * phi.shape[1] * np.log(n_eff))
    scores_array = np.array(scores)
    weights = np.exp(scores_array - scores_array.max())
    return LawCurve(law, weights / weights.sum(), betas, covariances, float(scores_array.max()))
