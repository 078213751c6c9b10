"""Held-out scores of many candidate effects at once (``ema.calibration.held_out.score`` for each, in one set of
matrix products): a grid of candidates whose columns are free, and a grid of offsets whose size the physics fixes.
The rotary's selection scores every candidate on every window and on thirty noise copies, so it pays for one pass."""

from __future__ import annotations

import numpy as np

from ema.calibration.held_out import FOLD_RIDGE, fold_slices
from ema.calibration.limits import FOLDS
from ema.estimate.least_squares import ridge_solved


def score_grid(
    base: np.ndarray, candidates: np.ndarray, y: np.ndarray, folds: np.ndarray, ridge: float = FOLD_RIDGE
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``score`` of base (m, k) + each candidate's columns (m, G, c), all G at once: (cv_rss (G,),
    rss (G,), beta (G, k + c)). One pass builds every fold's Gram blocks (matrix products); the G
    small systems are solved together."""
    k, (g, c) = base.shape[1], candidates.shape[1:]
    blocks = np.zeros((FOLDS, g, k + c, k + c))
    rhs = np.zeros((FOLDS, g, k + c))
    yy = np.zeros(FOLDS)
    for f, rows in enumerate(fold_slices(folds)):
        x, z, target = base[rows], candidates[rows].reshape(-1, g * c), y[rows]
        blocks[f, :, :k, :k] = x.T @ x
        cross = (x.T @ z).reshape(k, g, c).transpose(1, 0, 2)
        blocks[f, :, :k, k:] = cross
        blocks[f, :, k:, :k] = cross.transpose(0, 2, 1)
        zz = z.reshape(-1, g, c)
        for i in range(c):
            for j in range(i, c):
                blocks[f, :, k + i, k + j] = blocks[f, :, k + j, k + i] = np.einsum(
                    "mg,mg->g", zz[:, :, i], zz[:, :, j]
                )
        rhs[f, :, :k] = x.T @ target
        rhs[f, :, k:] = (target @ z).reshape(g, c)
        yy[f] = target @ target
    total_b, total_r, total_y = blocks.sum(0), rhs.sum(0), yy.sum()
    cv = np.zeros(g)
    for f in range(FOLDS):
        beta = ridge_solved(total_b - blocks[f], total_r - rhs[f], ridge)
        cv += yy[f] - 2 * np.sum(beta * rhs[f], axis=1) + _quadratic(beta, blocks[f])
    beta = ridge_solved(total_b, total_r, ridge)
    rss = total_y - 2 * np.sum(beta * total_r, axis=1) + _quadratic(beta, total_b)
    return cv, np.maximum(rss, 0.0), beta


def _quadratic(beta: np.ndarray, gram: np.ndarray) -> np.ndarray:
    """βᵀGβ for each of G systems."""
    return np.sum(beta * np.matmul(gram, beta[..., None])[..., 0], axis=1)


def score_offsets(
    base: np.ndarray, offsets: np.ndarray, y: np.ndarray, folds: np.ndarray, ridge: float = FOLD_RIDGE
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``score`` of y − offsets[:, g] on the base design (m, k), for each of G offsets (m, G) at once: a
    candidate whose size the physics fixes (coefficient 1), only its grid value free. Returns
    (cv_rss (G,), rss (G,), beta (G, k))."""
    targets = y[:, None] - offsets  # (m, G)
    k = base.shape[1]
    gram, rhs, yy = np.zeros((FOLDS, k, k)), np.zeros((FOLDS, k, offsets.shape[1])), np.zeros((FOLDS, offsets.shape[1]))
    for f, rows in enumerate(fold_slices(folds)):
        x, t = base[rows], targets[rows]
        gram[f], rhs[f], yy[f] = x.T @ x, x.T @ t, np.einsum("mg,mg->g", t, t)
    total_g, total_r, total_y = gram.sum(0), rhs.sum(0), yy.sum(0)
    cv = np.zeros(offsets.shape[1])
    for f in range(FOLDS):
        beta = ridge_solved(total_g - gram[f], total_r - rhs[f], ridge)  # (k, G)
        cv += yy[f] - 2 * np.sum(beta * rhs[f], axis=0) + np.sum(beta * (gram[f] @ beta), axis=0)
    beta = ridge_solved(total_g, total_r, ridge)
    rss = total_y - 2 * np.sum(beta * total_r, axis=0) + np.sum(beta * (total_g @ beta), axis=0)
    return cv, np.maximum(rss, 0.0), beta.T
