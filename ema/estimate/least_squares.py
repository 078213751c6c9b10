"""Least squares, written once: every design in ema is solved here.

- ``coefficients``: y on a design by NumPy's SVD solver; a column the rows cannot tell from another gets the
  minimum-norm share, never an infinite one.
- ``weighted``: each row weighed by 1/variance, through the normal equations' pseudo-inverse, with the
  coefficients' covariance and χ² (a trend's, a law's, a drive's calibration).
- ``ridge_solved``: normal equations given as sums (a Gram matrix and its right-hand side, or a stack of them),
  a relative ridge keeping a collinear column solvable: what held-out folds solve from per-fold sums.
- ``newey_west_std``: each coefficient's std where the residual is correlated over samples (Newey and West's
  sandwich with Bartlett weights, their plug-in number of lags).

Eq. 5.1's profile search over η_O (``ema.kinds.rotary.physics.eta_search``) solves its few normal equations inside
its compiled kernel, row by row of a batch, for speed.
"""

from __future__ import annotations

import numpy as np

# An offset needs motion both ways: with fewer than this share of the samples in the rarer direction,
# it cannot be told from the dry friction and is not solved (every kind's least squares holds to it).
MIN_OFFSET_BALANCE = 0.05


def coefficients(design: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(K,) or (K, M): the least-squares coefficients of y (N,) or (N, M) on ``design`` (N, K)."""
    return np.linalg.lstsq(design, y, rcond=None)[0]


def weighted(design: np.ndarray, y: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(coefficients (K,), their covariance (K, K), χ²) of y (N,) on ``design`` (N, K), each row weighed by
    ``weight`` (N,) = 1/variance: the normal equations solved through their pseudo-inverse, so that a column the
    rows cannot tell from another gets no share rather than an infinite one."""
    gram = design.T @ (weight[:, None] * design)
    covariance = np.linalg.pinv(gram)
    beta = covariance @ design.T @ (weight * y)
    return beta, covariance, float(np.sum(weight * (y - design @ beta) ** 2))


def ridge_solved(gram: np.ndarray, rhs: np.ndarray, ridge: float) -> np.ndarray:
    """The solution of (G + ridge·diag(G))·β = b: ``gram`` (K, K) with ``rhs`` (K,) or (K, M), or a stack
    (S, K, K) with (S, K). The ridge is relative to each column's own scale, so that it keeps a column no sample
    tells from another solvable without moving a column the samples do tell."""
    if gram.ndim == 2:
        scale = np.maximum(np.diag(gram), 1e-300)
        return _solved(gram + ridge * np.diag(scale), rhs)
    scale = np.maximum(np.einsum("gkk->gk", gram), 1e-300)
    regularized = gram + ridge * scale[:, :, None] * np.eye(gram.shape[1])[None]
    return _solved(regularized, rhs[..., None])[..., 0]


def _solved(gram: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """G⁻¹b; where G is singular (a column no row holds, with no ridge), the minimum-norm solution instead."""
    try:
        return np.linalg.solve(gram, rhs)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(gram) @ rhs


def newey_west_lags(n: int) -> int:
    """The residual's correlation lags the std weighs: Newey and West's (1994) plug-in, 4·(n/100)^(2/9)."""
    return int(4.0 * (n / 100.0) ** (2.0 / 9.0))


def newey_west_std(x: np.ndarray, residual: np.ndarray, lags: int | None = None) -> np.ndarray:
    """Each coefficient's std from the sandwich (XᵀX)⁻¹·S·(XᵀX)⁻¹, S the residual's long-run covariance with
    Bartlett weights 1 − k/(lags + 1); ``lags`` None: Newey and West's plug-in for the residual's length."""
    lags = newey_west_lags(len(residual)) if lags is None else lags
    inverse = np.linalg.pinv(x.T @ x)
    scores = x * residual[:, None]
    s = scores.T @ scores
    for k in range(1, lags + 1):
        shifted = scores[k:].T @ scores[:-k]
        s += (1.0 - k / (lags + 1.0)) * (shifted + shifted.T)
    return np.sqrt(np.clip(np.diag(inverse @ s @ inverse), 0.0, None))
