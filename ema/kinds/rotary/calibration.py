"""The calibration loop as one estimator: residuals -> noise floor -> candidates -> selection -> report.

``Calibrator`` has the scikit-learn shape: ``__init__`` stores settings, ``fit(windows, truth)``
checks them and runs the stages once each, in order, and leaves ``report_`` (the
``ema-calibration/1`` document) and the residuals a figure needs:

First ``ema.kinds.rotary.pipeline`` estimates each window with the base model, the document's alone (the answer
before; ``ema estimate`` also takes a sensor's offset off and reads the viscous coefficient). Then the
stages, numbered as their modules and ``docs/calibration.md`` number them:

1. ``ema.kinds.rotary.equations``: the windows' equation-error problem;
2. ``ema.kinds.rotary.noise_floor``: the same problem on noise-only copies;
3. ``ema.kinds.rotary.families``, ``vocabulary``: each effect as a family of columns;
4. ``ema.kinds.rotary.selection``: what explains held-out samples beyond the floor, named or described
   (``ema.kinds.rotary.twins`` for look-alikes, ``ema.kinds.rotary.backlash`` for the dead band);
5. ``ema.kinds.rotary.readings``: the effect against its rivals' readings, adopted only where they agree
   (an ambiguity keeps the base estimates, its stds widened), never where it reads worse;
6. ``ema.kinds.rotary.tied_solve``: the estimates with what is adopted, checked on held-out folds;
7. ``ema.kinds.rotary.calibration_report``: the document.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ema.calibration.documents import RotaryCalibration, Step
from ema.calibration.limits import MAX_EFFECTS
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import TARGETS, Estimate
from ema.kinds.rotary import calibration_report as reporting
from ema.kinds.rotary.backlash import read_backlash
from ema.kinds.rotary.equations import Equations, equations
from ema.kinds.rotary.families import Family, generic_families
from ema.kinds.rotary.noise_floor import clean_replicas, noise_copies
from ema.kinds.rotary.physics.scenario import CLEAR_MARGIN
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.prepare.conditioning import prepare
from ema.kinds.rotary.readings import AMBIGUOUS_STDS, Contest, combined_stds, reading, settled
from ema.kinds.rotary.selection import Chosen, Decision, Evidence, decide, evidence
from ema.kinds.rotary.tied_solve import MIN_HELD_OUT_GAIN, corrected, held_out_rss, solve_with
from ema.kinds.rotary.twins import TWINS, output_error, runners_up, tell_apart
from ema.kinds.rotary.vocabulary import COGGING_ORDERS, named_families
from ema.model.actuator import RotaryActuator
from ema.model.bounds import DEFAULT_SAMPLE_RATE_HZ, NOISE_COPIES
from ema.model.checks import InputError
from ema.model.noise import SensorNoise
from ema.model.params import HealthRanges
from ema.model.window import RotaryWindow

# A std past this share of the healthy range does not place the actuator in it: a reading's move is judged on
# no wider a std (a base model a sensor fault defeats carried 3 N·m on FDJ, and then nothing counted as a move).
MOVE_SHARE_OF_RANGE = 0.5
SEPARATION = 0.5  # a rival's excess output error, as a share of the pick's gain over no effect, that tells them apart


def combined(results: Sequence[Estimate], actuator: RotaryActuator) -> dict[str, float]:
    """Inverse-variance mean of FDJ and η_O over windows (one actuator, one health); η_O the nominal where no
    window carries a load to read it by."""
    out = {}
    for name in TARGETS:
        entries = [e for e in (getattr(r.estimates, name) for r in results) if e is not None]
        if not entries:
            out[name] = actuator.health.efficiency
            continue
        values = np.array([e.value for e in entries])
        weights = 1.0 / np.maximum([e.std or 1.0 for e in entries], 1e-12) ** 2
        out[name] = float(values @ weights / weights.sum())
    return out


@dataclass(frozen=True)
class Context:
    """What every selection step reads: the windows' equations and noise copies, the windows, the base
    estimates, the sensors' noise and the pipeline's bias."""

    measured: Equations
    copies: Sequence[Equations]
    windows: Sequence[RotaryWindow]
    before: Mapping[str, float]
    stds: Mapping[str, float]
    noise: Sequence[SensorNoise]
    bias: Mapping[str, float]
    ranges: HealthRanges

    def moves(self, estimates: Mapping[str, float], reference: Mapping[str, float] | None = None) -> bool:
        """``estimates`` lie further from ``reference`` (the base ones) than ``AMBIGUOUS_STDS`` of their stds, each
        std at most ``MOVE_SHARE_OF_RANGE`` of the healthy range."""
        reference = self.before if reference is None else reference
        return any(abs(estimates[t] - reference[t]) > AMBIGUOUS_STDS * self._scale(t) for t in TARGETS)

    def _scale(self, target: str) -> float:
        low, high = self.ranges.of(target)
        return min(self.stds[target], MOVE_SHARE_OF_RANGE * (high - low))


def _told_apart(decision: Decision, pick: Evidence, options: Sequence[Evidence], narrow: Sequence[Evidence]) -> str:
    """A step's reason: why the family was decided, which one the simulation named, what it was told from."""
    others = [o.family.name for o in options if o is not pick]
    reason = decision.reason
    if pick is not decision.chosen:
        reason += f"; simulated, {pick.family.name} follows the windows best"
    if others:
        reason += f"; told from {' and '.join(others)} by the motor speed and current each reading predicts"
    if narrow:
        reason += f" (narrowly from {', '.join(o.family.name for o in narrow)}: nearly the same trace)"
    return reason


class Calibrator:
    def __init__(
        self,
        pipeline: PipelineConfig = PipelineConfig(),
        max_effects: int = MAX_EFFECTS,
        copies: int = NOISE_COPIES,
        seed: int = 0,
        *,
        actuator: RotaryActuator,
    ) -> None:
        self.actuator = actuator
        self.pipeline = pipeline
        self.max_effects = max_effects
        self.copies = copies
        self.seed = seed

    def _check(self, windows: Sequence[RotaryWindow]) -> list[RotaryWindow]:
        if not 1 <= self.max_effects <= 4:
            raise InputError("max_effects", f"must be in [1, 4], got {self.max_effects}")
        if not 8 <= self.copies <= 500:
            raise InputError("copies", f"must be in [8, 500], got {self.copies}")
        if not windows:
            raise InputError("windows", "at least one window is needed")
        # what departs is named, not taken off
        prepared = [prepare(w, self.actuator, spec_only=True).window for w in windows]
        if len({w.sample_rate_hz for w in prepared}) > 1:
            raise InputError(
                "windows", f"must share one sample rate (after averaging to at most {DEFAULT_SAMPLE_RATE_HZ:g} Hz)"
            )
        return prepared

    def fit(
        self,
        windows: Sequence[RotaryWindow],
        truth: Mapping[str, float] | None = None,
        on_stage: Callable[[str], None] | None = None,
        checkpoint: Callable[[], None] | None = None,
    ) -> Calibrator:
        """Run the stages once each (see the module docstring); ``on_stage`` hears each stage as it starts,
        ``checkpoint`` is called between the pieces of a stage (both may raise to stop the job there)."""
        stage = on_stage or (lambda _: None)
        check = checkpoint or (lambda: None)
        started = time.perf_counter()
        prepared = self._check(windows)
        stage(f"estimating {len(prepared)} window(s) with the base model")
        base = [
            estimate_window(w, self.pipeline, actuator=self.actuator, on_stage=lambda _: check(), spec_only=True)
            for w in prepared
        ]
        before = combined(base, self.actuator)
        stds = combined_stds([{n: getattr(getattr(r.estimates, n), "std", None) for n in TARGETS} for r in base])
        bias = {n: float(np.mean([r.methods[n].physics_bias for r in base])) for n in TARGETS}
        noise = [SensorNoise(**r.dataset.noise_estimated) for r in base if r.dataset is not None]
        rate = prepared[0].sample_rate_hz
        spec = self.actuator.params
        measured = equations([w.signals for w in prepared], rate, COGGING_ORDERS, spec)
        stage(f"simulating {self.copies} noise-only copies")
        clean = clean_replicas(prepared, before, self.actuator)
        copies = noise_copies(clean, noise, rate, COGGING_ORDERS, self.seed, spec, copies=self.copies, on_copy=check)
        families = named_families(measured, spec) + generic_families(measured)
        stage(f"scoring {len(families)} candidate families against the noise floor")
        self.contests_: dict[str, Contest] = {}
        context = Context(measured, copies, prepared, before, stds, noise, bias, self.actuator.ranges)
        chosen, steps, first_round, unnamed = self._select(context, families, check)
        chosen, ambiguity = settled(measured, chosen, self.contests_, bias, (before, stds))
        if ambiguity is not None:
            steps.append(Step(selected=None, reason=ambiguity.reason, indistinguishable_from=ambiguity.effects))
        held, chosen = self._held_out(measured, chosen)
        found = reporting.Found(measured, copies, first_round, chosen, steps, unnamed, read_backlash(measured, copies))
        found, held = reporting.adopt_described(found, held)
        adopted = found.adopted
        after = corrected(solve_with(measured, adopted).values, bias) if adopted else before
        self.measured_, self.chosen_ = measured, adopted
        report = reporting.assemble(
            found, before, after, bias, held, truth=truth, seconds=time.perf_counter() - started
        )
        stds_after = stds if ambiguity is None else ambiguity.stds_after
        self.report_: RotaryCalibration = report.model_copy(
            update={"stds_before": stds, "stds_after": stds_after, "ambiguity": ambiguity}
        )
        return self

    def _select(
        self, context: Context, families: Sequence[Family], check: Callable[[], None]
    ) -> tuple[list[Chosen], list[Step], list[Evidence], list[Evidence]]:
        """Forward selection; returns the chosen families, each step, the first round's evidence, and the
        curves that describe what no name matches (``check`` before each family is scored)."""
        measured, copies = context.measured, context.copies
        chosen: list[Chosen] = []
        steps: list[Step] = []
        first_round: list[Evidence] = []
        while len(chosen) < self.max_effects:
            taken = {c.family.name for c in chosen} | {t for c in chosen for t in TWINS.get(c.family.name, ())}
            found = []
            for family in (f for f in families if f.name not in taken):
                check()
                found.append(evidence(measured, copies, chosen, family))
            first_round = first_round or found
            decision = decide(found, measured, copies, chosen)
            if decision.chosen is None:
                steps.append(Step(selected=None, reason=decision.reason))
                return chosen, steps, first_round, decision.unnamed
            pick, step, narrow = self._name(decision, found, chosen, context)
            steps.append(step)
            if pick is None:
                return chosen, steps, first_round, []
            chosen.append(Chosen(pick.family, pick.grid))
            self.contests_[pick.family.name] = Contest(pick, narrow)
        return chosen, steps, first_round, []

    def _name(
        self, decision: Decision, found: Sequence[Evidence], chosen: Sequence[Chosen], context: Context
    ) -> tuple[Evidence | None, Step, list[Evidence]]:
        """The decided family, or the rival whose reading's simulation follows the windows clearly better (each
        simulated at its own re-estimated FDJ and η_O, beside the effects already chosen); None where its reading
        moves the estimates beyond their stds from the reading without it and its simulation follows the windows
        no better than the model without it (never worse, at every step). Also the rivals it could not tell from
        it clearly."""
        pick = decision.chosen
        assert pick is not None
        prior = reading(context.measured, chosen, context.bias) if chosen else context.before  # without it

        def read(o: Evidence) -> dict[str, float]:
            return reading(context.measured, [*chosen, Chosen(o.family, o.grid)], context.bias)

        readings = {pick.family.name: read(pick)}
        moved = context.moves(readings[pick.family.name], prior)
        options = [pick, *runners_up(pick, found, decision.alike, wide=moved)]
        readings |= {o.family.name: read(o) for o in options[1:]}
        args = (context.windows, context.noise, self.actuator)
        beside = [self.contests_[c.family.name].pick for c in chosen]  # simulated with every reading
        simulated, errors, clear = (
            tell_apart(args[0], readings, options, *args[1:], beside)
            if len(options) > 1
            else (
                pick,
                {pick.family.name: output_error(args[0], readings[pick.family.name], pick, *args[1:], beside)},
                True,
            )
        )
        pick = simulated if clear else pick  # a narrow call is noise: the held-out equations' choice stands
        best = errors[pick.family.name]
        judged = context.moves(readings[pick.family.name], prior)
        base = output_error(args[0], prior, None, *args[1:], beside) if judged else float("inf")
        if best > (1 - CLEAR_MARGIN) * base:
            reason = (
                f"{decision.reason}; but simulated with it at its estimates the windows' speed and current are "
                f"followed no better than without it ({best:.3g} against {base:.3g}): not adopted"
            )
            return None, Step(selected=None, reason=reason, tie_break_output_error={**errors, "none": base}), []
        # where its reading moves the estimates, a rival is told apart only by a margin of at least SEPARATION of
        # the pick's own margin over the model without it: the simulation must tell them apart about as clearly
        # as it tells the effect from none, or the windows hold two readings (``readings.settled``)
        margin = max(CLEAR_MARGIN * best, SEPARATION * (base - best) if np.isfinite(base) else 0.0)
        narrow = [o for o in options if o is not pick and errors[o.family.name] <= best + margin]
        reason = _told_apart(decision, pick, options, narrow)
        shown = {**errors, **({"none": base} if np.isfinite(base) else {})}
        step = Step(
            selected=pick.family.name,
            reason=reason,
            indistinguishable_from=[o.family.name for o in narrow]
            or [a for a in decision.alike if a != pick.family.name],
            tie_break_output_error=shown,
        )
        return pick, step, narrow

    def _held_out(self, measured: Equations, chosen: list[Chosen]) -> tuple[reporting.HeldOutCheck, list[Chosen]]:
        """Keep each effect, in the order chosen, only if re-estimated with it the model predicts
        held-out folds better than without it."""
        before = held_out_rss(measured, [])
        kept: list[Chosen] = []
        current, dropped = before, []
        for c in chosen:
            trial = held_out_rss(measured, [*kept, c])
            if trial < (1.0 - MIN_HELD_OUT_GAIN) * current:
                kept.append(c)
                current = trial
            else:
                dropped.append(c.family.name)
        if not chosen:
            note = "no effect to adopt"
        elif not kept:
            note = "re-estimated with the effects, the model does not predict held-out folds better: base model kept"
        else:
            note = f"re-estimated with {', '.join(c.family.name for c in kept)}, the model predicts held-out folds "
            note += f"{100 * (1 - current / before):.0f} % better"
            note += f"; {', '.join(dropped)} did not help on held-out folds and was left out" if dropped else ""
        return reporting.HeldOutCheck(before, current, bool(kept), note), kept
