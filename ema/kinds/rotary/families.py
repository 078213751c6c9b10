"""Stage 3, candidates: each effect as a family of equation-error columns, and the generic curves.

A ``Family`` is one candidate: its columns in Eq. 5.1's equation error given its one nonlinear parameter
(a grid value), what its coefficients mean, and the term the simulator adds for it. The named effects
are the vocabulary (``ema.kinds.rotary.vocabulary``); beside them, generic families (piecewise-linear
curves over time, speed, load and current) say what the residual follows when no name matches; over
time, speed or position they are also a term the simulator can add (``simulator.effects.FrictionTable``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.hats import hats, uniform_knots
from ema.kinds.rotary.simulator.effects import EffectSet, FrictionTable

KNOTS = 9  # piecewise-linear curves: 8 segments over the visited range
# A friction that changes in time (warming, wear-in) does so smoothly over one log: a line with one
# bend. Eight free segments would spend their freedom on noise, and lose on held-out samples to any
# one-column shape that merely correlates with time (the direction, when the elevator turns once).
TIME_KNOTS = 3

Grid = Any  # a family's nonlinear parameter: a float (ω_s, order p), a (centre, width) pair, or nan
Columns = Callable[[Equations, Grid], np.ndarray]
Parameters = Callable[[np.ndarray, Grid], dict[str, float]]
Term = Callable[[np.ndarray, Grid], EffectSet | None]


@dataclass(frozen=True)
class Family:
    name: str  # an effect of the vocabulary, or "friction vs <variable>" for a generic curve
    follows: str  # the variable its trace follows
    named: bool
    columns: Columns  # (m, k) design columns, given the grid value
    parameters: Parameters  # from its coefficients: what the report states
    term: Term  # what the simulator adds, or None where it cannot
    grid: tuple[Grid, ...] = (float("nan"),)  # its one nonlinear parameter, if any
    # Whether its variable is imposed on the transmission rather than a response of it: the current
    # answers the friction itself, so a curve over it mimics any large effect and may not block a name.
    exogenous: bool = True
    stacked: Callable[[Equations], np.ndarray] | None = None  # (m, G, c): every grid value's columns at once
    # For the tied solve (``ema.kinds.rotary.tied_solve``): columns of the base replaced (a hinge-moment bias
    # moves the load a and o are built from, and their coefficients stay k_aid and k_opp), and how
    # many of ``columns`` are left as free terms (the others are that replacement's first order).
    base_shift: Callable[[Equations, Grid], np.ndarray] | None = None
    free_columns: int | None = None
    # The physics fixes the size (a gain's trace, given the gain): its one column enters with
    # coefficient 1, subtracted from t, and only the grid value is solved.
    offset: bool = False
    # Its grid is the effect's size (a gain, an offset, a bias): a best value at either end is a bound, not a
    # reading, and the effect is larger than any the loop names.
    sized: bool = False

    def grid_columns(self, e: Equations) -> np.ndarray:
        """(m, G, c) columns for every grid value."""
        if self.stacked is not None:
            return self.stacked(e)
        return np.stack([self.columns(e, g) for g in self.grid], axis=1)


def _table(variable: str, knots: np.ndarray, beta: np.ndarray) -> EffectSet:
    values = np.clip(np.concatenate([[0.0], beta]), -0.5, 0.5)
    return EffectSet(table=FrictionTable(variable, float(knots[0]), float(knots[1] - knots[0]), tuple(values)))


def _curve(knots: np.ndarray, unit: str) -> Parameters:
    def parameters(beta: np.ndarray, _: float) -> dict[str, float]:
        values = np.concatenate([[0.0], beta])
        return {f"{x:.4g} {unit}": float(v) for x, v in zip(knots, values, strict=True)}

    return parameters


GENERIC = {  # variable: (the simulator's table for it, unit, knots)
    "time_s": ("time", "s", TIME_KNOTS),
    "position_rad": ("position", "rad", KNOTS),
    "speed_radps": ("speed", "rad/s", KNOTS),
    "load_nm": (None, "N·m", KNOTS),
    "current_a": (None, "A", KNOTS),
}


def generic_families(measured: Equations) -> list[Family]:
    """Piecewise-linear friction against each variable no name covers as such."""
    families = []
    for variable, (table, unit, count) in GENERIC.items():
        knots = uniform_knots(measured.variables[variable], count)

        def term(b: np.ndarray, g: Grid, table: str | None = table, knots: np.ndarray = knots) -> EffectSet | None:
            return None if table is None else _table(table, knots, b)

        def columns(e: Equations, g: Grid, variable: str = variable, knots: np.ndarray = knots) -> np.ndarray:
            return hats(e.variables[variable], knots)

        families.append(
            Family(
                f"friction vs {variable}",
                variable,
                False,
                columns,
                _curve(knots, unit),
                term,
                exogenous=variable != "current_a",
            )
        )
    return families
