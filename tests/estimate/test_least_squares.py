"""The one least squares: known coefficients come back, weights and ridges do what they say, and the Newey–West
std covers the spread of a slope under correlated noise (drawn here by an AR(1) process, not by the code)."""

import numpy as np
import pytest

from ema.estimate.least_squares import coefficients, newey_west_lags, newey_west_std, ridge_solved, weighted


def _design(rng: np.random.Generator, n: int = 400) -> np.ndarray:
    return np.column_stack([np.ones(n), rng.normal(size=n), np.sin(np.linspace(0, 9, n))])


def test_known_coefficients_come_back_for_one_target_and_several():
    rng = np.random.default_rng(1)
    x, truth = _design(rng), np.array([0.5, -2.0, 3.0])
    assert coefficients(x, x @ truth) == pytest.approx(truth, abs=1e-12)
    two = np.column_stack([x @ truth, x @ (2 * truth)])
    assert coefficients(x, two) == pytest.approx(np.column_stack([truth, 2 * truth]), abs=1e-12)


def test_equal_weights_give_the_plain_solution_and_the_covariance_scales_with_the_variance():
    rng = np.random.default_rng(2)
    x = _design(rng)
    y = x @ np.array([1.0, 0.3, -0.7]) + rng.normal(0.0, 0.1, len(x))
    beta, covariance, chi2 = weighted(x, y, np.full(len(x), 1 / 0.01))
    assert beta == pytest.approx(coefficients(x, y), abs=1e-10)
    assert covariance == pytest.approx(0.01 * np.linalg.inv(x.T @ x), rel=1e-8)
    assert chi2 == pytest.approx(np.sum((y - x @ beta) ** 2) / 0.01, rel=1e-10)


def test_the_ridge_leaves_a_told_column_alone_and_keeps_a_collinear_one_finite():
    rng = np.random.default_rng(3)
    x = _design(rng)
    gram, rhs = x.T @ x, x.T @ (x @ np.array([1.0, 2.0, 3.0]))
    assert ridge_solved(gram, rhs, 1e-10) == pytest.approx([1.0, 2.0, 3.0], rel=1e-7)
    twins = np.column_stack([x, x[:, 1]])  # a column no sample tells from another
    solved = ridge_solved(twins.T @ twins, twins.T @ (x @ np.array([1.0, 2.0, 3.0])), 1e-10)
    assert np.all(np.isfinite(solved)) and solved[1] + solved[3] == pytest.approx(2.0, rel=1e-6)
    stack = np.stack([gram, 2 * gram])
    assert ridge_solved(stack, np.stack([rhs, rhs]), 1e-10) == pytest.approx(
        np.stack([ridge_solved(gram, rhs, 1e-10), ridge_solved(2 * gram, rhs, 1e-10)]), rel=1e-10
    )


def test_the_newey_west_std_covers_a_slopes_spread_under_correlated_noise():
    rng = np.random.default_rng(4)
    n, rho = 600, 0.8
    x = np.column_stack([np.ones(n), np.linspace(-1, 1, n)])
    slopes, stds, white = [], [], []
    for _ in range(300):
        shocks = rng.normal(size=n)
        noise = np.empty(n)
        noise[0] = shocks[0]
        for i in range(1, n):
            noise[i] = rho * noise[i - 1] + np.sqrt(1 - rho**2) * shocks[i]
        beta = coefficients(x, noise)
        residual = noise - x @ beta
        slopes.append(beta[1])
        stds.append(newey_west_std(x, residual, newey_west_lags(n) * 4)[1])
        white.append(newey_west_std(x, residual, 0)[1])
    spread = float(np.std(slopes))
    assert np.mean(stds) == pytest.approx(spread, rel=0.25)  # the sandwich with lags sees the correlation
    assert np.mean(white) < 0.6 * spread  # without lags it does not


def test_without_a_ridge_a_column_no_row_holds_gets_no_share():
    """A fold without one direction of motion leaves that direction's column zero: the others are read as without
    it, and it gets the minimum-norm share, 0, not an error."""
    rng = np.random.default_rng(4)
    x = _design(rng)
    y = x @ np.array([1.0, 2.0, 3.0])
    empty = np.column_stack([x, np.zeros(len(x))])
    solved = ridge_solved(empty.T @ empty, empty.T @ y, 0.0)
    assert solved == pytest.approx([1.0, 2.0, 3.0, 0.0], abs=1e-9)
    stacked = ridge_solved(np.stack([empty.T @ empty] * 2), np.stack([empty.T @ y] * 2), 0.0)
    assert stacked == pytest.approx(np.stack([solved, solved]), abs=1e-9)
