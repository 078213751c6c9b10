"""Stage 5, one reading or several: an effect is adopted only where no rival reads the windows as well and
moves the estimates elsewhere.

Each effect selection would adopt is set against its **rivals**: its twins where the simulation could
not tell them apart clearly (``ema.kinds.rotary.twins``), and the other named families that explain
about as much of the held-out residual (within ``NAME_MARGIN``; where the effect's reading moves the
estimates, of the measured residual too). The windows are re-estimated with each
in its place (``ema.kinds.rotary.tied_solve``). Where a rival's estimates differ from the effect's by more
than ``AMBIGUOUS_STDS`` of the base estimates' stds, the windows hold two readings and the evidence does
not choose: neither is adopted, the base estimates are kept, their stds are widened until ±2 std holds
every reading, and the report names the readings and the data that would tell them apart. Where
every rival agrees with the effect within those stds, the effect is adopted: the estimates do not
depend on which name is right.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ema.calibration.documents import Ambiguity
from ema.estimate.documents import TARGETS
from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.selection import Chosen, Evidence
from ema.kinds.rotary.tied_solve import corrected, solve_with

AMBIGUOUS_STDS = 2.0
# What would tell two look-alike effects apart, by the pair (either order).
TELL_APART = {
    frozenset({"inertia", "current_sensor_gain"}): "a window that rests on an end stop while the motor pushes, or "
    "moves at a constant speed under a changing load: current with no acceleration",
    frozenset({"inertia", "torque_constant"}): "a window that rests on an end stop while the motor pushes, or moves "
    "at a constant speed under a changing load: current with no acceleration",
    frozenset({"torque_constant", "current_sensor_gain"}): "a window near the motor's top speed, where the back-EMF "
    "(k_e = k_T) limits the current",
    frozenset({"hinge_moment_bias", "current_sensor_offset"}): "a ground window with no load, or motion both ways "
    "under one load",
    frozenset({"viscous", "stribeck"}): "a window moving both slowly and fast",
}
DEFAULT_TELL_APART = "windows where the two differ: another command family, or another load"


@dataclass(frozen=True)
class Contest:
    """An effect selection would adopt, and the named families that read the windows about as well."""

    pick: Evidence
    rivals: list[Evidence] = field(default_factory=list)


def reading(measured: Equations, terms: Sequence[Chosen], bias: Mapping[str, float]) -> dict[str, float]:
    """FDJ and η_O re-estimated with ``terms``, the base pipeline's bias off."""
    return corrected(solve_with(measured, terms).values, bias)


def what_tells_apart(names: Sequence[str]) -> str:
    return TELL_APART.get(frozenset(names[:2]), DEFAULT_TELL_APART)


def settled(
    measured: Equations,
    kept: Sequence[Chosen],
    contests: Mapping[str, Contest],
    bias: Mapping[str, float],
    base: tuple[Mapping[str, float], Mapping[str, float]],
) -> tuple[list[Chosen], Ambiguity | None]:
    """``kept`` up to the first effect whose rivals read the windows elsewhere, and that ambiguity (None where
    there is none). ``base``: the base model's (estimates, stds)."""
    before, stds = base
    adopted: list[Chosen] = []
    for c in kept:
        contest = contests.get(c.family.name)
        rivals = [] if contest is None else contest.rivals
        mine = reading(measured, [*adopted, c], bias)
        others = {r.family.name: reading(measured, [*adopted, Chosen(r.family, r.grid)], bias) for r in rivals}
        apart = {
            name: values
            for name, values in others.items()
            if any(abs(values[t] - mine[t]) > AMBIGUOUS_STDS * stds[t] for t in TARGETS)
        }
        if apart:
            readings = {c.family.name: mine, **apart}
            return adopted, _ambiguity(readings, before, stds)
        adopted.append(c)
    return adopted, None


def _ambiguity(
    readings: dict[str, dict[str, float]], before: Mapping[str, float], stds: Mapping[str, float]
) -> Ambiguity:
    names = list(readings)
    widened = {t: float(max(stds[t], max(abs(r[t] - before[t]) for r in readings.values()) / 2.0)) for t in TARGETS}
    return Ambiguity(
        effects=names,
        readings=readings,
        stds_after=widened,
        tell_apart=what_tells_apart(names),
        reason=f"{' and '.join(names)} read the windows about as well and put FDJ or η_O more than "
        f"{AMBIGUOUS_STDS:g} stds apart: neither is adopted, the base estimates are kept with stds that hold both",
    )


def combined_stds(stds: Sequence[Mapping[str, float | None]]) -> dict[str, float]:
    """The inverse-variance std of FDJ and η_O over windows (inf where no window read one)."""
    out = {}
    for t in TARGETS:
        known = np.array([s[t] for s in stds if s.get(t)], dtype=float)
        out[t] = float(1.0 / np.sqrt(np.sum(1.0 / known**2))) if len(known) else float("inf")
    return out
