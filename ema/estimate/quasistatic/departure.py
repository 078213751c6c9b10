"""Whether a friction reading departs from the healthy actuator, either way: one rule for a window and for a set.

A reading departs where it lies farther from the nominal than ``DEPARTURE_Z`` times what healthy readings
allow: how far a healthy set's mean sits off the nominal (another load, another day), and the reading's own
repeatability std (over the runs' count, for a set's mean). Where the reading's load lies outside those the
healthy runs were learned at, the nominal is extrapolated there and its constants (η_O, c) no longer cancel:
their part of the std joins it, and the reading says so (it cannot show a change smaller than that). A friction
that falls departs as a rising one does: a ball screw that loses its preload loses friction.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ema.estimate.stats import DECISIVE_Z

DEPARTURE_Z = DECISIVE_Z
LOAD_TOLERANCE = 0.1  # a load within this share of the learned range's ends is inside it


@dataclass(frozen=True)
class Departure:
    change: float  # reading − nominal
    allowed: float  # one std of what healthy readings allow
    extrapolated: bool  # the load lies outside the learned ones

    @property
    def z(self) -> float:
        return self.change / max(self.allowed, 1e-300)

    @property
    def departed(self) -> bool:
        return abs(self.z) > DEPARTURE_Z


def inside(load_n: float, learned_n: Sequence[float] | None) -> bool:
    """Whether a (signed) load lies within the range the healthy runs were learned at (True where none is kept)."""
    if not learned_n:
        return True
    low, high = min(learned_n), max(learned_n)
    margin = LOAD_TOLERANCE * max(abs(low), abs(high))
    return low - margin <= load_n <= high + margin


def departure(
    value: float,
    nominal: float,
    *,
    repeatability_std: float,
    shared_std: float,
    healthy_set: float,
    runs: int = 1,
    extrapolated: bool = False,
) -> Departure:
    """A reading (one window's, or the mean of ``runs`` windows') against the nominal (module docstring)."""
    allowed = float(np.sqrt(healthy_set**2 + repeatability_std**2 / runs + (shared_std**2 if extrapolated else 0.0)))
    return Departure(value - nominal, allowed, extrapolated)
