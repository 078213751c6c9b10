"""Stage 7, the report: the ``ema-calibration/1`` document from what the stages found."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, replace

import numpy as np

from ema.calibration.documents import Candidate, HeldOut, NoiseFloor, RotaryCalibration, Step, Unexplained
from ema.estimate.documents import TARGETS
from ema.estimate.profile import ETA_O_SEARCH
from ema.kinds.rotary.backlash import BacklashReading
from ema.kinds.rotary.equations import Equations
from ema.kinds.rotary.selection import Chosen, Evidence, floor_rms, residual_rms
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.tied_solve import MIN_HELD_OUT_GAIN, corrected, held_out_rss, solve_with

# How much further noise alone may move FDJ or η_O with a described term than without it before the
# estimates with it are withheld: a time drift inflates them 1–2.5x, a ramp over deflection 13–32x.
MAX_TERM_INFLATION = 5.0


@dataclass(frozen=True)
class Found:
    measured: Equations
    copies: Sequence[Equations]
    evidence: Sequence[Evidence]  # every family, first round
    chosen: Sequence[Chosen]
    steps: Sequence[Step]
    unnamed: Sequence[Evidence]
    backlash: BacklashReading
    described: Chosen | None = None  # the generic term adopted where no name matches (``adopt_described``)

    @property
    def adopted(self) -> list[Chosen]:
        """Every term the estimates after are solved with: the named effects, then the described one."""
        return [*self.chosen, *([self.described] if self.described else [])]


@dataclass(frozen=True)
class HeldOutCheck:
    rss_before: float  # held-out residual of the base model re-estimated on each four folds [N·m²]
    rss_after: float  # ...and with the effects
    adopted: bool
    note: str


def _candidate(e: Evidence) -> Candidate:
    return Candidate(
        effect=e.family.name,
        follows=e.family.follows,
        named=e.family.named,
        parameters=e.family.parameters(e.beta, e.grid),
        rms_reduction=e.rms_reduction,
        held_out_drop=e.improvement,
        score=e.z,
        plausible=e.family.term(e.beta, e.grid) is not None,
    )


def _backlash_candidate(reading: BacklashReading) -> Candidate:
    return Candidate(
        effect="backlash",
        follows="direction",
        named=True,
        parameters={"extra_rad": reading.extra_rad},
        rms_reduction=0.0,
        held_out_drop=0.0,
        score=reading.z,
        plausible=-5e-3 <= reading.extra_rad <= 0.1,
    )


def adopted_effects(found: Found) -> EffectSet:
    """The simulator's terms for everything adopted (one friction table at most: the first)."""
    evidence = {e.family.name: e for e in found.evidence}
    terms = [c.family.term(evidence[c.family.name].beta, c.grid) for c in found.chosen]
    if found.described is not None:
        lead = found.unnamed[0]
        terms.append(lead.family.term(lead.beta, lead.grid))  # a friction table: no parameters of its own
    effects = EffectSet.combined(term for term in terms if term is not None)
    if found.backlash.significant:
        effects = effects.with_effect("backlash", extra_rad=float(np.clip(found.backlash.extra_rad, -5e-3, 0.1)))
    return effects


def _errors(values: Mapping[str, float], truth: Mapping[str, float] | None) -> dict[str, float] | None:
    """|value − truth| of FDJ and η_O, those the truth names (None: it names neither, or no truth)."""
    if truth is None:
        return None
    return {k: abs(values[k] - float(truth[k])) for k in TARGETS if k in truth} or None


def scatter(copies: Sequence[Equations], with_it: Sequence[Chosen]) -> np.ndarray:
    """Relative std of FDJ and η_O, solved with ``with_it``, over the noise-only copies."""
    solutions = np.array([[solve_with(c, with_it).values[n] for n in TARGETS] for c in copies])
    return solutions.std(axis=0) / np.abs(solutions.mean(axis=0))


def withheld(found: Found, with_it: Sequence[Chosen], estimates: Mapping[str, float], has_term: bool) -> str | None:
    """Why the estimates with a described term are not offered, or None where they are. Where the
    load columns mimic the term (a ramp over deflection, which the hinge moment follows; a curve
    over current, which answers the friction itself), FDJ and η_O trade with it: noise alone then
    moves them many times further than without it, or drives η_O to the end of its search."""
    if not has_term:
        return "the simulator has no term for this variable"
    low, high = ETA_O_SEARCH
    if not (estimates["FDJ"] > 0 and low + 1e-3 < estimates["eta_O"] < high - 1e-3):
        return "with this term η_O goes to the end of its range: the estimates are not identified"
    inflation = float(np.max(scatter(found.copies, with_it) / scatter(found.copies, found.chosen)))
    if inflation > MAX_TERM_INFLATION:
        return (
            f"with this term noise alone moves FDJ or η_O {inflation:.0f}x as far as without it: "
            "the load columns mimic it, and the estimates with it are not identified"
        )
    return None


def adopt_described(found: Found, held: HeldOutCheck) -> tuple[Found, HeldOutCheck]:
    """``found`` with the lead described term adopted, and the held-out check with it, where the simulator
    can add the term, the estimates with it are identified (``withheld``) and the model with it predicts
    held-out folds better than without it, as a named effect must; else both unchanged. Never where the
    windows cannot tell which variable the residual follows, or which of two named effects: a curve over
    the wrong one trades with FDJ and η_O (docs/calibration.md, step 5)."""
    if len({e.family.follows for e in found.unnamed}) != 1 or found.unnamed[0].family.named:
        return found, held
    lead = found.unnamed[0]
    term = lead.family.term(lead.beta, lead.grid)
    described = Chosen(lead.family, lead.grid)
    with_it = [*found.chosen, described]
    if withheld(
        found, with_it, solve_with(found.measured, with_it).values, term is not None and term.table is not None
    ):
        return found, held
    current = held.rss_after if held.adopted else held.rss_before
    trial = held_out_rss(found.measured, with_it)
    if trial >= (1.0 - MIN_HELD_OUT_GAIN) * current:
        return found, held
    note = f"{held.note}; the described term ({lead.family.name}) adopted: held-out folds "
    note += f"{100 * (1 - trial / current):.0f} % better with it"
    return replace(found, described=described), HeldOutCheck(held.rss_before, trial, True, note)


def unexplained(found: Found, bias: Mapping[str, float], truth: Mapping[str, float] | None) -> Unexplained | None:
    if not found.unnamed:
        return None
    lead = found.unnamed[0]
    variables = list(dict.fromkeys(e.family.follows for e in found.unnamed))
    term = lead.family.term(lead.beta, lead.grid)
    table = None if term is None else term.table
    with_it = [*found.chosen, Chosen(lead.family, lead.grid)]
    raw = solve_with(found.measured, with_it).values
    reason = withheld(found, with_it, raw, table is not None)
    estimates = None if reason else corrected(raw, bias)
    if lead.family.named:
        names = " or ".join(dict.fromkeys(e.family.name for e in found.unnamed))
        described = f"the residual torque follows {variables[0]} as {names} would: these windows cannot tell which"
    elif len(variables) == 1:
        described = f"the residual torque follows {variables[0]} in a shape no named effect has (table below)"
    else:
        described = f"the residual torque follows {' or '.join(variables)}: these windows cannot tell which"
    return Unexplained(
        adopted=found.described is not None,
        variables=variables,
        description=described,
        shape=lead.family.parameters(lead.beta, lead.grid),
        simulator_term=None if table is None else asdict(table),
        estimates_if_added=estimates,
        estimates_withheld=reason,
        residual_rms_if_added=residual_rms(found.measured, with_it),
        error_if_added=None if estimates is None else _errors(estimates, truth),
    )


def assemble(
    found: Found,
    before: Mapping[str, float],
    after: Mapping[str, float],
    bias: Mapping[str, float],
    held: HeldOutCheck,
    *,
    truth: Mapping[str, float] | None,
    seconds: float,
) -> RotaryCalibration:
    floor = floor_rms(found.copies)
    effects = adopted_effects(found)
    names = [c.family.name for c in found.chosen] + (["backlash"] if found.backlash.significant else [])
    first = next((e for e in found.evidence if found.chosen and e.family.name == found.chosen[0].family.name), None)
    return RotaryCalibration(
        n_windows=int(found.measured.window.max()) + 1,
        noise_floor=NoiseFloor(copies=len(found.copies), equation_error_ratio=residual_rms(found.measured, []) / floor),
        residual_rms_before={"residual_torque": residual_rms(found.measured, [])},
        residual_rms_after={"residual_torque": residual_rms(found.measured, found.adopted)},
        candidates=[*(_candidate(e) for e in found.evidence), _backlash_candidate(found.backlash)],
        selected_effect=names[0] if names else None,
        selected_effects=names,
        selected_parameters=None if first is None else first.family.parameters(first.beta, first.grid),
        effects={**effects.as_dict(), **({"table": asdict(effects.table)} if effects.table else {})},
        selection_steps=list(found.steps),
        unexplained=unexplained(found, bias, truth),
        held_out=HeldOut(rss_before=held.rss_before, rss_after=held.rss_after, adopted=held.adopted, note=held.note),
        estimates_before=dict(before),
        estimates_after=dict(after),
        timings_s={"total": seconds},
    )
