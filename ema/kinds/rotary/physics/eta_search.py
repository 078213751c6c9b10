"""Eq. 5.1's search over η_O: for each window's sums Σ z·zᵀ, the η_O, FDJ and nuisances of least SSE.

With η_A tied to η_O by Eq. 3.4, the model t = FDJ + k_aid·a + k_opp·o (+ nuisances) is linear in
everything but η_O. At each η_O of a grid, u = t − k_aid·a − k_opp·o is regressed on (1, nuisances…)
in closed form from the sums alone, and the grid is refined around its best point (the SSE is smooth
and unimodal in η_O). A solution and its block jackknife solve thousands of such rows per window, so the
search runs in one compiled pass (``_search``); ``tests/kinds/rotary/physics`` holds the plain vectorized
form it must equal.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ema.estimate.least_squares import MIN_OFFSET_BALANCE
from ema.estimate.profile import ETA_O_SEARCH
from ema.model.params import eta_a_of, load_factors

GRID_POINTS = 41
REFINEMENTS = 3  # coarse-to-fine passes: η_O to ~1e-5
# ΔC, γ and ΔJ need columns that vary: with a coefficient of variation below this, they cannot be told
# from FDJ and are not solved (an offset's motion both ways: ``MIN_OFFSET_BALANCE``).
MIN_VARIATION = 0.05
RIDGE = 1e-12  # relative: two nuisances nearly dependent (speeds set by the direction) stay solvable


def coarse_to_fine(score: Callable[[np.ndarray], np.ndarray]) -> tuple[float, np.ndarray, int]:
    """(best η_O, the last grid, the best's index in it) of ``score`` (G,) -> (G,), minimized over ``GRID_POINTS``
    points of ``ETA_O_SEARCH``, ``REFINEMENTS`` times, each grid spanning ± one step around the last one's best
    (the score is smooth and unimodal in η_O). ``_search`` runs the same schedule compiled, row by row."""
    low, high = ETA_O_SEARCH
    for _ in range(REFINEMENTS):
        grid = np.linspace(low, high, GRID_POINTS)
        best = int(np.argmin(score(grid)))
        step = grid[1] - grid[0]
        low, high = max(grid[best] - step, ETA_O_SEARCH[0]), min(grid[best] + step, ETA_O_SEARCH[1])
    return float(grid[best]), grid, best


def solved_terms(stats: np.ndarray, nuisances: tuple[str, ...]) -> np.ndarray:
    """(R, F) which of (FDJ, *nuisances) each row's window can tell apart (FDJ always; the rest by their
    column's balance or variation; ``stats`` (R, P, P), z = (t, a, o, nuisances…, 1))."""
    m = stats[:, -1, -1]
    used = [m > 0]
    for i, name in enumerate(nuisances, start=3):
        total, square = stats[:, i, -1], stats[:, i, i]
        if name == "offset":
            used.append((m > 0) & (m - np.abs(total) >= 2 * MIN_OFFSET_BALANCE * m))  # 2 × the rarer direction's
        else:
            used.append((m > 0) & (square * m - total**2 > (MIN_VARIATION * total) ** 2))
    return np.stack(used, axis=-1)


def solve(stats: np.ndarray, gear: float, nuisances: tuple[str, ...] = ()) -> tuple[np.ndarray, ...]:
    """(coefficients (R, F): FDJ then the nuisances', η_O (R,), SSE (R,)) per row of ``stats`` (R, P, P).

    A term a row's window cannot tell (``solved_terms``) gets coefficient 0.
    """
    stats = np.ascontiguousarray(stats, dtype=np.float64)
    free = np.array([stats.shape[-1] - 1, *range(3, 3 + len(nuisances))], dtype=np.int64)  # the constant first
    used = solved_terms(stats, nuisances)
    unit_grid = np.linspace(0.0, 1.0, GRID_POINTS)
    beta = np.zeros((len(stats), len(free)))
    eta_o, sse = np.empty(len(stats)), np.empty(len(stats))
    _search((stats, free, used, float(gear)), (unit_grid, *ETA_O_SEARCH, REFINEMENTS), (beta, eta_o, sse))
    return beta, eta_o, sse


# Eq. 3.4 and the load factors are plain Python in ema.model (the documents import them without Numba); registered
# here, the kernel compiles the one definition.
register_jitable(eta_a_of)
register_jitable(load_factors)


@njit(cache=True, nogil=True, error_model="numpy")
def _search(problem, grid, out):
    """Fill ``out`` = (beta (R, F), eta_o (R,), sse (R,)) for ``problem`` = (stats (R, P, P), ``free`` (F,) the
    columns regressed on (the constant first), ``used`` (R, F), the gear ratio) on ``grid`` = (``unit_grid``
    (G,) = linspace(0, 1, G), the lowest and highest η, the refinements):

        k_opp = 1/η − 1,  k_aid = 1 − η_A(η),  u = t − k_aid·a − k_opp·o,
        β = (Zᵀ Z)⁻¹ Zᵀ u over the used terms,  SSE = uᵀu − βᵀ Zᵀu,

    at each η of ``refinements`` grids, each spanning ± one step around the last one's best point.
    """
    stats, free, used, gear = problem
    unit_grid, low_bound, high_bound, refinements = grid
    beta, eta_o, sse = out
    n_free = free.shape[0]
    scratch = (np.empty((n_free, n_free)), np.empty(n_free))  # the Gram matrix and its right side, as solved
    rhs, b = np.empty(n_free), np.empty(n_free)
    for r in range(stats.shape[0]):
        s = stats[r]
        low, high = low_bound, high_bound
        for _ in range(refinements):
            step = (low + (high - low) * unit_grid[1]) - low
            best, best_eta, best_sse = -1, 0.0, np.inf
            for g in range(unit_grid.shape[0]):
                eta = low + (high - low) * unit_grid[g]
                k_aid, k_opp = load_factors(eta, gear)
                uu = (
                    s[0, 0]
                    + k_aid**2 * s[1, 1]
                    + k_opp**2 * s[2, 2]
                    - 2 * k_aid * s[0, 1]
                    - 2 * k_opp * s[0, 2]
                    + 2 * k_aid * k_opp * s[1, 2]
                )
                for f in range(n_free):
                    cross = s[0, free[f]] - k_aid * s[1, free[f]] - k_opp * s[2, free[f]]
                    rhs[f] = cross if used[r, f] or n_free == 1 else 0.0
                if n_free == 1:  # FDJ alone: u's mean over the sliding samples, no solve
                    b[0] = rhs[0] / max(s[-1, -1], 1.0)
                else:
                    _regression(s, free, used[r], rhs, scratch, b)
                value = uu
                for f in range(n_free):
                    value -= b[f] * rhs[f]
                if best < 0 or value < best_sse or (np.isnan(value) and not np.isnan(best_sse)):
                    best, best_eta, best_sse = g, eta, value
                    beta[r, :] = b
            low, high = max(best_eta - step, low_bound), min(best_eta + step, high_bound)
        eta_o[r], sse[r] = best_eta, best_sse


@njit(cache=True, nogil=True, inline="always")
def _regression(s, free, used, rhs, scratch, b):
    """b = (Zᵀ Z)⁻¹ Zᵀ u over the ``used`` terms, a term not used getting an identity row (so 0); ``scratch``
    = (gram (F, F), work (F,)), overwritten."""
    gram, work = scratch
    n_free = free.shape[0]
    for f in range(n_free):
        work[f] = rhs[f]
        for h in range(n_free):
            gram[f, h] = s[free[f], free[h]] if used[f] and used[h] else 0.0
        gram[f, f] = gram[f, f] * (1.0 + RIDGE) if used[f] else 1.0
    _gauss(gram, work, b)


@njit(cache=True, nogil=True, inline="always")
def _gauss(a, y, x):
    """x = a⁻¹·y by elimination with partial pivoting; ``a`` and ``y`` are overwritten."""
    n = y.shape[0]
    for col in range(n):
        pivot = col
        for row in range(col + 1, n):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        if pivot != col:
            for k in range(n):
                a[col, k], a[pivot, k] = a[pivot, k], a[col, k]
            y[col], y[pivot] = y[pivot], y[col]
        for row in range(col + 1, n):
            factor = a[row, col] / a[col, col]
            for k in range(col, n):
                a[row, k] -= factor * a[col, k]
            y[row] -= factor * y[col]
    for row in range(n - 1, -1, -1):
        acc = y[row]
        for k in range(row + 1, n):
            acc -= a[row, k] * x[k]
        x[row] = acc / a[row, row]
