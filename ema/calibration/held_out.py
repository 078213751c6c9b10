"""Held-out folds, written once: a design's residual where each fold is predicted by the solution on the others.

Every kind's calibration scores a model so (``FOLDS`` folds, ``ema.calibration.limits``); each kind says how its
rows fall into them (the rotary's interleaved blocks of every window, the servo's contiguous fifths of each log).
The Gram matrices of each fold are summed once, so a solution without fold f is (G − G_f)⁻¹(b − b_f) and its
held-out error y_fᵀy_f − 2βᵀb_f + βᵀG_fβ: a candidate costs one pass over the samples, a grid of them one set of
matrix products, and a noise floor of thirty simulated copies stays cheap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.calibration.limits import FOLDS
from ema.estimate.least_squares import ridge_solved

FOLD_RIDGE = 1e-10  # relative: keeps a collinear column (two hats with no sample between) solvable


@dataclass(frozen=True)
class Scored:
    cv_rss: float  # held-out residual sum of squares, all folds
    rss: float  # in-sample
    beta: np.ndarray  # coefficients from all samples, in design order
    fold_rss: np.ndarray  # (FOLDS,) each fold's held-out residual sum of squares


def fold_sums(design: np.ndarray, y: np.ndarray, folds: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per fold: XᵀX (F, k, k), Xᵀy (F, k), yᵀy (F,)."""
    k = design.shape[1]
    gram, rhs, yy = np.zeros((FOLDS, k, k)), np.zeros((FOLDS, k)), np.zeros(FOLDS)
    for f, rows in enumerate(fold_slices(folds)):
        x, target = design[rows], y[rows]
        gram[f], rhs[f], yy[f] = x.T @ x, x.T @ target, target @ target
    return gram, rhs, yy


def score(design: np.ndarray, y: np.ndarray, folds: np.ndarray, ridge: float = FOLD_RIDGE) -> Scored:
    """Held-out and in-sample solution of ``y`` on ``design`` (m, k); ``ridge``: relative, 0 for plain least squares
    where no two columns can coincide."""
    gram, rhs, yy = fold_sums(design, y, folds)
    total_g, total_b, total_y = gram.sum(0), rhs.sum(0), yy.sum()
    fold_rss = np.zeros(FOLDS)
    cv = 0.0
    for f in range(FOLDS):
        beta = ridge_solved(total_g - gram[f], total_b - rhs[f], ridge)
        fold_rss[f] = yy[f] - 2 * beta @ rhs[f] + beta @ gram[f] @ beta
        cv += fold_rss[f]
    beta = ridge_solved(total_g, total_b, ridge)
    rss = total_y - 2 * beta @ total_b + beta @ total_g @ beta
    return Scored(float(cv), float(max(rss, 0.0)), beta, fold_rss)


def fold_slices(folds: np.ndarray) -> list[slice | np.ndarray]:
    """Each fold's rows: a slice where the samples are grouped by fold (the rotary's equations are), else their
    indices."""
    out: list[slice | np.ndarray] = []
    for f in range(FOLDS):
        rows = np.flatnonzero(folds == f)
        contiguous = len(rows) and rows[-1] - rows[0] + 1 == len(rows)
        out.append(slice(int(rows[0]), int(rows[-1]) + 1) if contiguous else rows)
    return out
