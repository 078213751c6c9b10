"""Held-out folds: the grid fast path equals solving each design alone; each fold's residual is what a solve without
it leaves there."""

import numpy as np
import pytest

from ema.calibration.held_out import score
from ema.calibration.limits import FOLDS
from ema.kinds.rotary.candidate_scores import score_grid


def _problem(seed: int, m: int = 600):
    rng = np.random.default_rng(seed)
    base = np.column_stack([np.ones(m), rng.normal(size=(m, 2))])
    grid = rng.normal(size=(m, 7, 2))
    y = base @ [1.0, 0.5, -0.2] + grid[:, 3] @ [0.3, 0.1] + 0.1 * rng.normal(size=m)
    folds = np.sort(np.arange(m) % FOLDS)  # grouped by fold, as ema.kinds.rotary.equations stores them
    return base, grid, y, folds


def test_the_grid_fast_path_equals_one_design_at_a_time():
    base, grid, y, folds = _problem(0)
    cv, rss, beta = score_grid(base, grid, y, folds)
    for g in range(grid.shape[1]):
        plain = score(np.concatenate([base, grid[:, g]], axis=1), y, folds)
        assert cv[g] == pytest.approx(plain.cv_rss, rel=1e-9)
        assert rss[g] == pytest.approx(plain.rss, rel=1e-9)
        np.testing.assert_allclose(beta[g], plain.beta, rtol=1e-7, atol=1e-12)
    assert int(np.argmin(cv)) == 3  # the column that made y


def test_held_out_error_exceeds_in_sample_and_recovers_the_coefficients():
    base, grid, y, folds = _problem(1)
    solved = score(np.concatenate([base, grid[:, 3]], axis=1), y, folds)
    assert solved.cv_rss > solved.rss
    np.testing.assert_allclose(solved.beta, [1.0, 0.5, -0.2, 0.3, 0.1], atol=0.02)


def test_each_folds_residual_is_what_a_solve_on_the_others_leaves_there():
    """Against NumPy's SVD solver on the rows of the other folds, folds interleaved (not grouped by fold)."""
    base, grid, y, _ = _problem(2)
    design = np.concatenate([base, grid[:, 3]], axis=1)
    folds = np.arange(len(y)) % FOLDS
    solved = score(design, y, folds)
    for f in range(FOLDS):
        out = folds == f
        beta = np.linalg.lstsq(design[~out], y[~out], rcond=None)[0]
        assert solved.fold_rss[f] == pytest.approx(float(np.sum((y[out] - design[out] @ beta) ** 2)), rel=1e-9)
    assert solved.cv_rss == pytest.approx(float(solved.fold_rss.sum()), rel=1e-12)
