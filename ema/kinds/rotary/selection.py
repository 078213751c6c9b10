"""Stage 4, selection: which family explains held-out samples beyond the noise floor, and may it be named.

For each family (``ema.kinds.rotary.families``) the statistic is the drop of held-out residual
(``ema.calibration.held_out``), as a fraction of the base model's: on the measured windows, and on
every noise copy (``ema.kinds.rotary.noise_floor``), where a family with a grid takes its best grid
value on each copy as it does on the data (the look-elsewhere freedom is in the floor). Its
evidence is z = (measured − mean of copies) / std of copies.

A family enters when z ≥ ``NAME_Z``. The one that explains held-out samples best is named only if
no curve over *another* variable explains nearly as much (``NAME_MARGIN``): a friction drifting
in time is not a position effect because the elevator happened to move while it drifted. When a
generic curve wins and a named family over the same variable comes within the margin, the name
is kept (the simpler shape); when none does, the report describes the curve instead of forcing
a name. Between two named families over the same variable that explain about as much, the one with
fewer shapes to choose from is kept unless the other explains held-out samples beyond it. Up to
``MAX_EFFECTS`` families enter, one at a time, each judged given the ones before.
The backlash lives in its own channel (``backlash``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ema.calibration.held_out import Scored, score
from ema.calibration.limits import NAME_Z, noise_z
from ema.kinds.rotary.candidate_scores import score_grid, score_offsets
from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.families import Family, Grid
from ema.model import runtime

NAME_MARGIN = 0.15  # a rival curve explaining ≥ 85 % as much leaves the name undecided


@dataclass(frozen=True)
class Chosen:
    family: Family
    grid: Grid


@dataclass(frozen=True)
class Evidence:
    family: Family
    grid: Grid
    improvement: float  # fractional drop of held-out residual on the measured windows
    null_mean: float
    null_std: float
    rms_reduction: float  # 1 − √(in-sample RSS with it / without)
    beta: np.ndarray  # its coefficients on the measured windows
    at_bound: bool = False  # a sized family's best value at an end of its grid (``Family.sized``)

    @property
    def z(self) -> float:
        return noise_z(self.improvement, self.null_mean, self.null_std)


def problem(e: Equations, chosen: Sequence[Chosen]) -> tuple[np.ndarray, np.ndarray]:
    """(design, target): the base columns with η_A tied to η_O (``Equations.tied``) and the chosen families'
    columns at their grid values; t less the tie's fixed part and the chosen families whose size the physics
    fixes."""
    base, fixed = e.tied
    columns = [c.family.columns(e, c.grid) for c in chosen if not c.family.offset]
    offsets = [c.family.columns(e, c.grid)[:, 0] for c in chosen if c.family.offset]
    return np.concatenate([base, *columns], axis=1), e.y - fixed - sum(offsets, np.zeros(e.m))


def residual_rms(e: Equations, chosen: Sequence[Chosen]) -> float:
    """RMS of the equation error [N·m] with the base columns and ``chosen``'s."""
    design, target = problem(e, chosen)
    return float(np.sqrt(score(design, target, e.folds).rss / e.m))


def floor_rms(copies: Sequence[Equations]) -> float:
    """The base model's equation error on noise-only copies: what noise alone leaves [N·m]."""
    return float(np.mean([residual_rms(c, []) for c in copies]))


def _drops(e: Equations, chosen: Sequence[Chosen], family: Family) -> tuple[np.ndarray, Scored, np.ndarray, np.ndarray]:
    """Per grid value, the fractional held-out drop of ``family`` added to the base and ``chosen``;
    with the base's own score, and each grid value's in-sample RSS and coefficients."""
    base_design, target = problem(e, chosen)
    base = score(base_design, target, e.folds)
    candidates = family.grid_columns(e)  # (m, G, c)
    if family.offset:
        cv, rss, _ = score_offsets(base_design, candidates[:, :, 0], target, e.folds)
        return 1.0 - cv / base.cv_rss, base, rss, np.ones((len(cv), 1))
    cv, rss, beta = score_grid(base_design, candidates, target, e.folds)
    return 1.0 - cv / base.cv_rss, base, rss, beta[:, base_design.shape[1] :]


def evidence(measured: Equations, copies: Sequence[Equations], chosen: Sequence[Chosen], family: Family) -> Evidence:
    """The family's drop on the data, at its best grid value, against the copies' best drops."""
    drops, base, rss, beta = _drops(measured, chosen, family)
    best = int(np.argmax(drops))
    # The copies are independent and their array work releases the GIL: spread over the simulator's threads.
    null = runtime.map_on_pool(lambda copy: float(np.max(_drops(copy, chosen, family)[0])), copies)
    return Evidence(
        family=family,
        grid=family.grid[best],
        improvement=float(drops[best]),
        null_mean=float(np.mean(null)),
        null_std=float(np.std(null, ddof=1)),
        rms_reduction=1.0 - float(np.sqrt(rss[best] / max(base.rss, 1e-300))),
        beta=beta[best],
        at_bound=family.sized and best in (0, len(family.grid) - 1),
    )


@dataclass(frozen=True)
class Decision:
    chosen: Evidence | None  # the family to adopt now, or None
    unnamed: list[Evidence]  # curves that explain the residual when no name may be given (best first)
    reason: str
    alike: list[str] = field(default_factory=list)  # named families this window cannot tell from the chosen one


def _width(e: Evidence) -> int:
    return len(e.beta)


def settle(
    named: Evidence, rival: Evidence, measured: Equations, copies: Sequence[Equations], chosen: Sequence[Chosen]
) -> str:
    """Between a named family and a curve over another variable that explains about as much: does
    either still explain held-out samples once the other is in? Returns "named", "rival" or "tie"."""
    rival_beyond = evidence(measured, copies, [*chosen, Chosen(named.family, named.grid)], rival.family).z >= NAME_Z
    named_beyond = evidence(measured, copies, [*chosen, Chosen(rival.family, rival.grid)], named.family).z >= NAME_Z
    if rival_beyond and not named_beyond:
        return "rival"
    if named_beyond or not rival_beyond:
        # Both carry something of their own (the named one enters now, the curve may later), or
        # neither does: then the fewer columns decide, and a curve against a curve stays open.
        return "named" if named_beyond or _width(named) < _width(rival) else "tie"
    return "tie"


def simplest(
    named: Evidence,
    close: Sequence[Evidence],
    measured: Equations,
    copies: Sequence[Equations],
    chosen: Sequence[Chosen],
) -> tuple[Evidence, list[str]]:
    """A named family over the same variable with fewer shapes to choose from, if ``named`` explains
    nothing beyond it: a Stribeck decay of the slowest scale is a straight line in speed over the
    visited range, and its grid should not win a viscous friction by a hair. The second value names
    the family set aside that way: the window cannot tell the two apart, and the report says so (a
    small Stribeck decay over 120–300 rad/s is named viscous that way, with a negative coefficient)."""
    simpler = [
        e
        for e in close
        if e.family.named and e.family.follows == named.family.follows and len(e.family.grid) < len(named.family.grid)
    ]
    for rival in sorted(simpler, key=lambda e: len(e.family.grid)):
        if evidence(measured, copies, [*chosen, Chosen(rival.family, rival.grid)], named.family).z < NAME_Z:
            return rival, [named.family.name]
    return named, []


def decide(
    found: Sequence[Evidence], measured: Equations, copies: Sequence[Equations], chosen: Sequence[Chosen]
) -> Decision:
    """One forward step: adopt the best significant family if a name is earned; else describe."""
    significant = sorted((e for e in found if e.z >= NAME_Z and not e.at_bound), key=lambda e: -e.improvement)
    if not significant:
        bounded = [e.family.name for e in found if e.z >= NAME_Z and e.at_bound]
        if bounded:
            return Decision(None, [], f"{', '.join(bounded)} reads at the end of its search: larger than any it names")
        return Decision(None, [], f"no candidate lowers the held-out residual beyond {NAME_Z:g} noise-floor stds")
    best = significant[0]
    close = [e for e in significant[1:] if e.improvement >= (1 - NAME_MARGIN) * best.improvement]
    named = (
        best
        if best.family.named
        else next((e for e in close if e.family.named and e.family.follows == best.family.follows), None)
    )
    if named is None:
        return Decision(None, [best], f"the residual follows {best.family.follows} in a way no named effect describes")
    named, alike = simplest(named, [best, *close], measured, copies, chosen)
    if _falls_with_speed(named):
        decays = [e for e in found if e.family.name == "stribeck" and e.z >= NAME_Z]
        return Decision(
            None,
            [named, *decays],
            "friction falls with speed over the speeds visited: a viscous "
            "coefficient below the document's, or a Stribeck decay; FDJ "
            "depends on which, and these windows cannot tell",
        )
    drift = _step_in_time(named, found)
    if drift is not None:
        share = drift.improvement / named.improvement
        return Decision(
            None,
            [drift, named],
            f"friction drifting in time explains {share:.0%} of what "
            f"{named.family.name} does: where the motion mostly goes one way and "
            "then the other, sgn(ω) is a step in time",
        )
    rivals = [e for e in [best, *close] if not e.family.named and e.family.exogenous]
    rivals = [e for e in rivals if e.family.follows != named.family.follows]
    for rival in rivals:
        verdict = settle(named, rival, measured, copies, chosen)
        if verdict == "rival":
            return Decision(
                None,
                [rival],
                f"the residual follows {rival.family.follows}, beyond what "
                f"{named.family.name} explains: no named effect describes it",
            )
        if verdict == "tie":
            return Decision(None, [rival, named], _ambiguous(named, [rival]))
    reason = f"{named.family.name} explains held-out samples best (z = {named.z:.0f})"
    if alike:
        reason += f"; {', '.join(alike)} explains the same samples (one trace over the range visited): simpler named"
    return Decision(named, [], reason, alike)


def _falls_with_speed(named: Evidence) -> bool:
    """A viscous term below the document's: friction falling with speed is also what a Stribeck decay
    leaves over the speeds a window visits, and the two put different constants into FDJ (a decay's
    level at rest is friction, a line's intercept is not). Named, a small decay read as a negative
    viscous coefficient moved FDJ by its amplitude."""
    return named.family.name == "viscous" and float(named.beta[0]) < 0.0


def _step_in_time(named: Evidence, found: Sequence[Evidence]) -> Evidence | None:
    """The curve over time that explains within ``NAME_MARGIN`` as much as a family following the direction
    (a sensor off zero leaves sgn(ω)·c), or None. A curve over another variable is set aside when the named
    family explains held-out samples beyond it (``settle``); a step in time is not, as the few reversals that
    tell a step from a drift are the very samples both explain."""
    if named.family.follows != "direction":
        return None
    timed = [e for e in found if not e.family.named and e.family.follows == "time_s" and e.z >= NAME_Z]
    close = [e for e in timed if e.improvement >= (1 - NAME_MARGIN) * named.improvement]
    return close[0] if close else None


def _ambiguous(best: Evidence, rivals: Sequence[Evidence]) -> str:
    names = ", ".join(sorted({best.family.follows, *(r.family.follows for r in rivals)}))
    return f"curves over {names} explain the residual about equally: these windows cannot tell which it follows"
