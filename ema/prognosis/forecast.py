"""Where a parameter goes from here: curves drawn from every law in the share of its weight.

Each law contributes ``DRAWS`` × its weight curves (its shapes by their posterior, its coefficients
about them), plus a random slope of the spread the weighed laws' misses of later windows showed beyond
what they promised (``ema.prognosis.weigh``), evaluated from the first window to ``HORIZON`` times the
history's span past the last. The first time each curve reaches the threshold is one draw of the
crossing time; a curve that never reaches it within the horizon crosses at infinity. The spread of the
crossing times is then the coefficients' uncertainty and the law's together.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.prognosis.weigh import Weighed

DRAWS = 6000
HORIZON = 10.0  # spans of the history past its last window that the curves are followed
GRID = 600  # points over that horizon
PLAUSIBLE_WEIGHT = 0.05  # a law under this weight gives no "earliest plausible" crossing


@dataclass(frozen=True)
class Forecast:
    """Curves of one parameter from its last window on, drawn from the weighed laws."""

    t_first: float
    span: float  # time from the first window to the last, in the prognosis's unit
    s_future: np.ndarray  # (GRID,) s from the last window (1) to 1 + HORIZON
    curves: np.ndarray  # (draws, GRID)
    law_of_curve: np.ndarray  # (draws,) index of the law each curve was drawn from
    weights: np.ndarray  # (laws,)

    def times(self, s: np.ndarray) -> np.ndarray:
        return self.t_first + s * self.span

    def crossing(self, threshold: float, sign: float) -> np.ndarray:
        """(draws,) time from the last window to each curve's first crossing going ``sign``; 0 where it is past
        already, inf where it never gets there within the horizon (linear between grid points)."""
        gap = sign * (self.curves - threshold)  # < 0: not yet
        past = gap >= 0.0
        first = np.where(past.any(axis=1), past.argmax(axis=1), -1)
        s = self.s_future
        out = np.full(len(gap), np.inf)
        at_once = first == 0
        out[at_once] = 0.0
        rows = np.flatnonzero(first > 0)
        k = first[rows]
        before, after = gap[rows, k - 1], gap[rows, k]
        fraction = -before / np.maximum(after - before, 1e-300)
        crossing_s = s[k - 1] + fraction * (s[k] - s[k - 1])
        out[rows] = (crossing_s - 1.0) * self.span
        return out

    def slope_now(self) -> np.ndarray:
        """(draws,) each curve's slope at the last window, per unit of time."""
        return (self.curves[:, 1] - self.curves[:, 0]) / ((self.s_future[1] - self.s_future[0]) * self.span)


def forecast(weighed: Weighed, t_first: float, span: float, seed: int = 0) -> Forecast:
    """``DRAWS`` curves from the weighed laws, each law's share by its weight."""
    rng = np.random.default_rng(seed)
    s = np.linspace(1.0, 1.0 + HORIZON, GRID)
    counts = rng.multinomial(DRAWS, weighed.weights)
    curves, laws = [], []
    for index, (curve, count) in enumerate(zip(weighed.curves, counts, strict=True)):
        if count:
            curves.append(curve.curves(s, int(count), rng))
            laws.append(np.full(count, index))
    drifting = np.concatenate(curves) + weighed.drift * rng.standard_normal((DRAWS, 1)) * (s - 1.0)
    return Forecast(t_first, span, s, drifting, np.concatenate(laws), weighed.weights)
