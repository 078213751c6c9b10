"""The calibration loop as one estimator: residuals -> noise floor -> candidates -> selection -> report.

``Calibrator`` has the scikit-learn shape: ``__init__`` stores settings, ``fit(windows, truth)``
checks them and runs the stages once each, in order, and leaves ``report_`` (the
``ema-calibration/1`` document) and the residuals a figure needs:

1. ``ema.estimate.pipeline`` estimates each window with the base model, the document's alone (the answer before;
   ``ema estimate`` also takes a sensor's offset off and reads the viscous coefficient);
2. ``ema.calibration.equations`` turns the windows into their equation-error problem;
3. ``ema.calibration.noise_floor`` builds the same problem on noise-only copies;
4. ``ema.calibration.families`` and ``ema.calibration.selection`` find what explains held-out samples
   beyond the floor, name it or describe it (``ema.calibration.twins`` for look-alikes,
   ``ema.calibration.backlash`` for the dead band);
5. ``ema.calibration.refit`` re-estimates with the effect in, checks it holds on held-out folds;
6. ``ema.calibration.report`` assembles the document.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ema.calibration import report as reporting
from ema.calibration.backlash import read_backlash
from ema.calibration.documents import CalibrationReport, Step
from ema.calibration.equations import Equations, equations
from ema.calibration.families import COGGING_ORDERS, Family, generic_families, named_families
from ema.calibration.noise_floor import COPIES, clean_replicas, noise_copies
from ema.calibration.refit import MIN_HELD_OUT_GAIN, corrected, fit_with, held_out_rss
from ema.calibration.selection import MAX_EFFECTS, Chosen, Decision, Evidence, decide, evidence
from ema.calibration.twins import TWINS, tell_apart
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import TARGETS, Estimate
from ema.estimate.pipeline import estimate_window
from ema.estimate.prepare.conditioning import prepare
from ema.model.actuator import Actuator
from ema.model.checks import InputError
from ema.model.noise import SensorNoise
from ema.model.window import Window


def combined(results: Sequence[Estimate], actuator: Actuator) -> dict[str, float]:
    """Inverse-variance mean of FDJ and η_O over windows (one actuator, one health); η_O the nominal where no
    window carries a load to read it by."""
    out = {}
    for name in TARGETS:
        entries = [e for e in (getattr(r.estimates, name) for r in results) if e is not None]
        if not entries:
            out[name] = actuator.nominal.eta_o
            continue
        values = np.array([e.value for e in entries])
        weights = 1.0 / np.maximum([e.std or 1.0 for e in entries], 1e-12) ** 2
        out[name] = float(values @ weights / weights.sum())
    return out


class Calibrator:
    def __init__(
        self,
        pipeline: PipelineConfig = PipelineConfig(),
        max_effects: int = MAX_EFFECTS,
        copies: int = COPIES,
        seed: int = 0,
        *,
        actuator: Actuator,
    ) -> None:
        self.actuator = actuator
        self.pipeline = pipeline
        self.max_effects = max_effects
        self.copies = copies
        self.seed = seed

    def _check(self, windows: Sequence[Window]) -> list[Window]:
        if not 1 <= self.max_effects <= 4:
            raise InputError("max_effects", f"must be in [1, 4], got {self.max_effects}")
        if not 8 <= self.copies <= 500:
            raise InputError("copies", f"must be in [8, 500], got {self.copies}")
        if not windows:
            raise InputError("windows", "at least one window is needed")
        # what departs is named, not taken off
        prepared = [prepare(w, self.actuator, spec_only=True).window for w in windows]
        if len({w.sample_rate_hz for w in prepared}) > 1:
            raise InputError("windows", "must share one sample rate (after averaging to at most 10 kHz)")
        return prepared

    def fit(
        self,
        windows: Sequence[Window],
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
        bias = {n: float(np.mean([r.methods[n].physics_bias for r in base])) for n in TARGETS}
        noise = [SensorNoise(**r.dataset.noise_estimated) for r in base]
        rate = prepared[0].sample_rate_hz
        spec = self.actuator.params
        measured = equations([w.signals for w in prepared], rate, COGGING_ORDERS, spec)
        stage(f"simulating {self.copies} noise-only copies")
        clean = clean_replicas(prepared, before, self.actuator)
        copies = noise_copies(clean, noise, rate, COGGING_ORDERS, self.seed, spec, self.copies, on_copy=check)
        families = named_families(measured, spec) + generic_families(measured)
        stage(f"scoring {len(families)} candidate families against the noise floor")
        chosen, steps, first_round, unnamed = self._select(measured, copies, families, prepared, before, noise, check)
        held, chosen = self._held_out(measured, chosen)
        found = reporting.Found(
            measured, copies, first_round, chosen, steps, unnamed, read_backlash(measured, copies, chosen)
        )
        found, held = reporting.adopt_described(found, held)
        adopted = found.adopted
        after = corrected(fit_with(measured, adopted).values, bias) if adopted else before
        self.measured_, self.chosen_ = measured, adopted
        self.report_: CalibrationReport = reporting.assemble(
            found, before, after, bias, held, truth, time.perf_counter() - started
        )
        return self

    def _select(
        self,
        measured: Equations,
        copies: Sequence[Equations],
        families: Sequence[Family],
        windows: Sequence[Window],
        before: Mapping[str, float],
        noise: Sequence[SensorNoise],
        check: Callable[[], None],
    ) -> tuple[list[Chosen], list[Step], list[Evidence], list[Evidence]]:
        """Forward selection; returns the chosen families, each step, the first round's evidence, and the
        curves that describe what no name fits (``check`` before each family is scored)."""
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
            pick, step = self._name(decision, found, windows, before, noise)
            chosen.append(Chosen(pick.family, pick.grid))
            steps.append(step)
        return chosen, steps, first_round, []

    def _name(
        self,
        decision: Decision,
        found: Sequence[Evidence],
        windows: Sequence[Window],
        before: Mapping[str, float],
        noise: Sequence[SensorNoise],
    ) -> tuple[Evidence, Step]:
        """The decided family, or one of its twins if the simulation says so."""
        pick = decision.chosen
        assert pick is not None
        twins = [e for e in found if e.family.name in TWINS.get(pick.family.name, ())]
        if not twins:
            return pick, Step(selected=pick.family.name, reason=decision.reason, indistinguishable_from=decision.alike)
        options = [pick, *twins]
        simulated, errors, clear = tell_apart(windows, before, options, noise, self.actuator)
        pick = simulated if clear else pick  # a narrow call is noise: the held-out equations' choice stands
        others = [o.family.name for o in options if o is not pick]
        runner = min(others, key=errors.__getitem__)
        reason = f"{decision.reason}; told from {' and '.join(others)} by the motor speed and current it predicts"
        return pick, Step(
            selected=pick.family.name,
            reason=reason if clear else reason + f" (narrowly from {runner}: the two leave nearly the same trace)",
            indistinguishable_from=[] if clear else [runner],
            tie_break_output_error=errors,
        )

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
