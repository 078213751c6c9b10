"""The compiled η_O search equals the plain vectorized one, and finds a known truth."""

import numpy as np
import pytest

from ema.estimate.profile import ETA_O_SEARCH
from ema.kinds.rotary.physics.eta_search import GRID_POINTS, REFINEMENTS, solve, solved_terms
from ema.model.params import eta_a_from_eta_o

GEAR = 500.0


def plain_profile(stats, eta_o, nuisances):
    """The SSE and coefficients (R, G, F) on a grid (R, G), whole arrays at a time (the reference)."""
    k_opp = 1.0 / eta_o - 1.0
    k_aid = 1.0 - eta_a_from_eta_o(eta_o, GEAR)
    s = stats[:, None]
    uu = (
        s[..., 0, 0]
        + k_aid**2 * s[..., 1, 1]
        + k_opp**2 * s[..., 2, 2]
        - 2 * k_aid * s[..., 0, 1]
        - 2 * k_opp * s[..., 0, 2]
        + 2 * k_aid * k_opp * s[..., 1, 2]
    )
    free = [-1, *range(3, 3 + len(nuisances))]
    cross = s[..., 0, free] - k_aid[..., None] * s[..., 1, free] - k_opp[..., None] * s[..., 2, free]
    if not nuisances:
        fdj = cross[..., 0] / np.maximum(s[..., -1, -1], 1.0)
        return fdj[..., None], uu - fdj * cross[..., 0]
    used = solved_terms(stats, nuisances)[:, None, :]
    both = used[..., :, None] & used[..., None, :]
    gram = np.where(both, stats[:, free][:, :, free][:, None], 0.0)
    diagonal = np.where(used, np.diagonal(gram, axis1=-2, axis2=-1) * (1.0 + 1e-12), 1.0)
    gram = gram * ~np.eye(len(free), dtype=bool) + diagonal[..., None] * np.eye(len(free))
    rhs = np.where(used, cross, 0.0)
    beta = np.linalg.solve(np.broadcast_to(gram, (*rhs.shape, len(free))), rhs[..., None])[..., 0]
    return beta, uu - np.sum(beta * rhs, axis=-1)


def plain_solve(stats, nuisances):
    rows = np.arange(len(stats))
    low, high = np.full(len(stats), ETA_O_SEARCH[0]), np.full(len(stats), ETA_O_SEARCH[1])
    for _ in range(REFINEMENTS):
        grid = low[:, None] + (high - low)[:, None] * np.linspace(0.0, 1.0, GRID_POINTS)
        beta, sse = plain_profile(stats, grid, nuisances)
        best = np.argmin(sse, axis=1)
        step = grid[:, 1] - grid[:, 0]
        centre = grid[rows, best]
        low, high = np.maximum(centre - step, ETA_O_SEARCH[0]), np.minimum(centre + step, ETA_O_SEARCH[1])
    return beta[rows, best], centre, sse[rows, best]


def sums(rng, truth_fdj, truth_eta, nuisances, n=400, one_way=False):
    """Σ z·zᵀ of a drawn window whose t follows Eq. 5.1 at the truth (with noise), z = (t, a, o, nuisances, 1)."""
    a = np.abs(rng.normal(20e-3, 10e-3, n)) * (rng.random(n) < 0.5)
    o = np.where(a > 0, 0.0, np.abs(rng.normal(30e-3, 10e-3, n)))
    direction = np.ones(n) if one_way else np.sign(rng.normal(size=n))
    speed = rng.uniform(50, 400, n)
    columns = {"offset": direction, "viscous": speed, "inertia": rng.normal(0, 1e3, n)}
    k_opp, k_aid = 1 / truth_eta - 1, 1 - eta_a_from_eta_o(truth_eta, GEAR)
    t = truth_fdj + k_aid * a + k_opp * o + 2e-3 * direction * ("offset" in nuisances) + rng.normal(0, 1e-3, n)
    z = np.stack([t, a, o, *(columns[name] for name in nuisances), np.ones(n)])
    return z @ z.T


@pytest.mark.parametrize("nuisances", [(), ("offset",), ("offset", "viscous"), ("viscous", "inertia")])
def test_the_compiled_search_equals_the_plain_one(nuisances):
    rng = np.random.default_rng(7)
    stats = np.stack(
        [sums(rng, rng.uniform(0.03, 0.1), rng.uniform(0.4, 0.95), nuisances, one_way=i % 5 == 0) for i in range(30)]
        + [np.zeros((4 + len(nuisances),) * 2)]
    )
    fast, plain = solve(stats, GEAR, nuisances), plain_solve(stats, nuisances)
    for got, want in zip(fast, plain, strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-15)


def test_it_finds_the_truth_and_the_offset():
    stats = sums(np.random.default_rng(3), 0.057, 0.74, ("offset",), n=4000)[None]
    beta, eta_o, _ = solve(stats, GEAR, ("offset",))
    assert beta[0, 0] == pytest.approx(0.057, rel=0.01)
    assert beta[0, 1] == pytest.approx(2e-3, rel=0.05)
    assert eta_o[0] == pytest.approx(0.74, abs=0.01)


def test_an_offset_a_one_way_window_cannot_tell_gets_zero():
    stats = sums(np.random.default_rng(4), 0.05, 0.8, ("offset",), one_way=True)[None]
    assert not solved_terms(stats, ("offset",))[0, 1]
    assert solve(stats, GEAR, ("offset",))[0][0, 1] == 0.0
