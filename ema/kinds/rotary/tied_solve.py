"""Stage 6, the estimates once the effect is in: Eq. 5.1 with its columns, η_A tied by Eq. 3.4.

The same profile search over η_O as ``ema.kinds.rotary.physics.friction``, with FDJ and the effect's
coefficients solved in closed form at each point. The physics solution's bias on this window's
scenario, measured by the base pipeline on its held-out simulations, is subtracted as it is
there, so that before and after differ only by the effect. "Never worse" is judged the same
way: the model with the effect, solved on four folds, must predict the fifth better than the
base model does, over every fold (``held_out_rss``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ema.calibration.limits import FOLDS
from ema.estimate.least_squares import coefficients
from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.physics.eta_search import coarse_to_fine
from ema.kinds.rotary.selection import Chosen
from ema.model.params import load_factors

MIN_HELD_OUT_GAIN = 0.01  # a model with an effect must cut the held-out residual by at least 1 % to be adopted


@dataclass(frozen=True)
class TiedSolution:
    fdj_nm: float
    eta_o: float
    beta: np.ndarray  # FDJ, then the effect columns' coefficients

    @property
    def values(self) -> dict[str, float]:
        return {"FDJ": self.fdj_nm, "eta_O": self.eta_o}


def _extra(e: Equations, chosen: Sequence[Chosen]) -> np.ndarray:
    """FDJ's column and each effect's free columns."""
    columns = [e.base[:, :1]]
    for c in chosen:
        if not c.family.offset:
            columns.append(c.family.columns(e, c.grid)[:, : c.family.free_columns])
    return np.concatenate(columns, axis=1)


def _offset(e: Equations, chosen: Sequence[Chosen]) -> np.ndarray:
    """What the effects whose size the physics fixes take from t."""
    return sum((c.family.columns(e, c.grid)[:, 0] for c in chosen if c.family.offset), np.zeros(e.m))


def _loads(e: Equations, chosen: Sequence[Chosen]) -> np.ndarray:
    """(m, 2): the aiding and opposing load columns, as the chosen effects correct them."""
    loads = e.base[:, 1:3].copy()
    for c in chosen:
        if c.family.base_shift is not None:
            loads += c.family.base_shift(e, c.grid)
    return loads


def _target(y: np.ndarray, eta_o: float, loads: np.ndarray, gear_ratio: float) -> np.ndarray:
    """t minus the load-dependent friction at η_O: what FDJ and the effect must explain."""
    k_aid, k_opp = load_factors(np.asarray(eta_o, dtype=np.float64), gear_ratio)
    return y - k_aid * loads[:, 0] - k_opp * loads[:, 1]


def solve_with(e: Equations, chosen: Sequence[Chosen], rows: np.ndarray | None = None) -> TiedSolution:
    """The base model plus ``chosen``'s columns, η_O searched coarse to fine, on ``rows`` (all by default).

    The target at η_O is y − k_aid·a − k_opp·o, and least squares is linear in its target: one solve for
    y, a and o together gives the coefficients and the residual at every η_O of the grid as a mix of
    three (the same minimum-norm solution a solve per grid point finds, without the solves).
    """
    rows = np.arange(e.m) if rows is None else rows
    design, loads, y = _extra(e, chosen)[rows], _loads(e, chosen)[rows], (e.y - _offset(e, chosen))[rows]
    parts = np.column_stack([y, loads])  # (m, 3): y, a, o
    solved = coefficients(design, parts)  # (k, 3)
    residuals = parts - design @ solved

    def mixes(grid: np.ndarray) -> np.ndarray:  # (3, G): y − k_aid·a − k_opp·o at each η_O
        return np.vstack([np.ones(len(grid)), *(-k for k in load_factors(grid, e.gear_ratio))])

    eta_o, grid, best = coarse_to_fine(lambda grid: np.sum((residuals @ mixes(grid)) ** 2, axis=0))
    beta = solved @ mixes(grid)[:, best]
    return TiedSolution(float(beta[0]), eta_o, beta)


def held_out_rss(e: Equations, chosen: Sequence[Chosen]) -> float:
    """Σ over folds of the squared error on the fold of the model solved on the other four."""
    design, loads, y = _extra(e, chosen), _loads(e, chosen), e.y - _offset(e, chosen)
    total = 0.0
    for f in range(FOLDS):
        solved = solve_with(e, chosen, np.flatnonzero(e.folds != f))
        held = e.folds == f
        error = _target(y, solved.eta_o, loads, e.gear_ratio)[held] - design[held] @ solved.beta
        total += float(error @ error)
    return total


def corrected(values: Mapping[str, float], bias: Mapping[str, float]) -> dict[str, float]:
    return {name: values[name] - bias[name] for name in values}
