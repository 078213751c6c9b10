"""The tied refit: one solve for every η_O of the grid equals a solve per grid point; a known truth returns."""

import numpy as np
import pytest

from ema.calibration.limits import FOLDS
from ema.estimate.profile import ETA_O_SEARCH
from ema.kinds.rotary.equations import Equations, equations
from ema.kinds.rotary.families import generic_families
from ema.kinds.rotary.physics.eta_search import GRID_POINTS, REFINEMENTS
from ema.kinds.rotary.selection import Chosen
from ema.kinds.rotary.tied_solve import solve_with
from ema.kinds.rotary.vocabulary import named_families
from ema.model.actuator import THESIS
from ema.model.params import eta_a_from_eta_o
from ema.model.window import window_from_dict
from tests.foreign.effects import CASES
from tests.foreign.windows import draw

GEAR = THESIS.params.gear_ratio


def _plain_fit(e: Equations, design: np.ndarray, loads: np.ndarray, y: np.ndarray) -> tuple[float, np.ndarray]:
    """η_O and the coefficients by a least-squares solve at every grid point, coarse to fine."""
    low, high = ETA_O_SEARCH
    for _ in range(REFINEMENTS):
        grid = np.linspace(low, high, GRID_POINTS)
        solutions = []
        for eta in grid:
            target = y - (1 - eta_a_from_eta_o(eta, GEAR)) * loads[:, 0] - (1 / eta - 1) * loads[:, 1]
            beta = np.linalg.lstsq(design, target, rcond=None)[0]
            solutions.append((float(np.sum((target - design @ beta) ** 2)), beta))
        best = int(np.argmin([sse for sse, _ in solutions]))
        step = grid[1] - grid[0]
        low, high = max(grid[best] - step, ETA_O_SEARCH[0]), min(grid[best] + step, ETA_O_SEARCH[1])
    return float(grid[best]), solutions[best][1]


def _measured(case: str, seed: int) -> Equations:
    """A foreign window with ``case`` in the foreign simulator's own form, as calibration reads it."""
    drawn = draw(seed, "thesis", effects=CASES[case](np.random.default_rng(seed), 1.0))
    window = window_from_dict(drawn.document)
    return equations([window.signals], window.sample_rate_hz, [], drive=THESIS.params)


@pytest.mark.parametrize(
    ("case", "family"), [("position_friction", "position_friction"), ("stribeck", "friction vs speed_radps")]
)
def test_one_solve_for_the_grid_equals_a_solve_per_point(case, family):
    e = _measured(case, 5_601)
    found = {f.name: f for f in [*named_families(e, THESIS.params), *generic_families(e)]}[family]
    chosen = [Chosen(found, found.grid[len(found.grid) // 2])]
    extra = found.columns(e, chosen[0].grid)[:, : found.free_columns]
    for with_it, design in (([], e.base[:, :1]), (chosen, np.column_stack([e.base[:, :1], extra]))):
        solved = solve_with(e, with_it)
        eta_o, beta = _plain_fit(e, design, e.base[:, 1:], e.y)
        assert solved.eta_o == eta_o
        np.testing.assert_allclose(solved.beta, beta, rtol=1e-9, atol=1e-12)


def test_a_known_fdj_and_eta_o_come_back():
    rng = np.random.default_rng(8)
    m, fdj, eta_o = 4_000, 0.052, 0.78
    loads = np.abs(rng.normal(0.0, 0.4, size=(m, 2))) * (rng.random((m, 1)) < 0.5)
    k_aid, k_opp = 1 - float(eta_a_from_eta_o(eta_o, GEAR)), 1 / eta_o - 1
    y = fdj + k_aid * loads[:, 0] + k_opp * loads[:, 1] + rng.normal(0.0, 2e-3, m)
    e = Equations(
        y=y,
        base=np.column_stack([np.ones(m), loads]),
        variables={},
        cogging={},
        kinematic=np.zeros(m),
        folds=np.sort(np.arange(m) % FOLDS),
        window=np.zeros(m, dtype=int),
        gear_ratio=GEAR,
    )
    solved = solve_with(e, [])
    assert solved.fdj_nm == pytest.approx(fdj, rel=0.02)
    assert solved.eta_o == pytest.approx(eta_o, abs=0.01)
