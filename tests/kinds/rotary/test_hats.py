"""Held-out scoring: the grid fast path equals fitting each design alone; the curve basis is sound."""

import numpy as np
import pytest

from ema.calibration.limits import FOLDS
from ema.kinds.rotary.fold_scores import hats, score, score_grid, uniform_knots


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


def test_hats_are_a_partition_of_unity_without_the_first():
    x = np.linspace(-1, 3, 101)
    knots = uniform_knots(x, 5)
    basis = hats(x, knots)
    assert basis.shape == (101, 4)
    u = np.clip((x - knots[0]) / (knots[1] - knots[0]), 0.0, len(knots) - 1.0)  # held past the ends
    first = np.maximum(0.0, 1.0 - u)
    np.testing.assert_allclose(basis.sum(axis=1) + first, 1.0, atol=1e-12)
