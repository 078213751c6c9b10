"""The calibration loop: estimate, simulate, compare, trace the residual to an effect, add it, re-estimate.

``Calibrator`` follows the scikit-learn shape: settings checked in ``__init__``, ``fit(windows,
truth)`` returns self, and the ``ema-calibration/1`` report is ``report_``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from sim.checks import InputError
from sim.effects import EffectSet
from sim.params import DEFAULT_RANGES, ActuatorParams, HealthParams
from sim.residual import DEFAULT_DERIVATIVE_WINDOW_S
from sim.window import Window
from training.calibration.channels import Residuals, residuals
from training.calibration.library import BY_NAME, FOLLOWS, PRIMARY, refined, within_bounds
from training.calibration.selection import (
    HELD_OUT_GAIN,
    MIN_BIC_GAIN,
    MIN_STABILITY,
    Blocks,
    Choice,
    best_choice,
    candidate_columns,
    fit_model,
    held_out_gain,
    integrated_time,
    make_blocks,
    scores,
    stability,
    structure_left,
)
from training.dataset import scenario_from_window
from training.pipeline import PipelineConfig, estimate_window

SCHEMA = "ema-calibration/1"
TARGETS = ("FDJ", "eta_O")
SAME_SIGNATURE_BIC = 0.5  # closer than this, two candidates leave the same trace: either may be named
# Between that and MIN_BIC_GAIN the windows favour one only weakly: no name is forced.
MAX_BLOCK_FRACTION = 20  # at least 20 blocks per window


def combined_estimates(results: Sequence[dict[str, Any]]) -> dict[str, float]:
    """Inverse-variance mean of FDJ and η_O over windows (the same actuator, the same health)."""
    combined = {}
    for name in TARGETS:
        values = np.array([r["estimates"][name]["value"] for r in results])
        weights = 1.0 / np.maximum([r["estimates"][name]["std"] for r in results], 1e-12) ** 2
        combined[name] = float(values @ weights / weights.sum())
    return combined


def simulate_like(window: Window, estimates: Mapping[str, float], effects: EffectSet) -> dict[str, np.ndarray]:
    """The window as the model (with ``effects``) produces it at ``estimates`` (FSJ nominal), clean."""
    health = HealthParams.single(DEFAULT_RANGES.nominal_fsj_nm, estimates["FDJ"], estimates["eta_O"])
    return scenario_from_window(window, effects).simulate(health).simulation(0)


class Calibrator:
    def __init__(
        self,
        pipeline: PipelineConfig = PipelineConfig(),
        actuator: ActuatorParams = ActuatorParams(),
        refinements: int = 2,
        seed: int = 0,
    ) -> None:
        if not isinstance(pipeline, PipelineConfig):
            raise InputError("pipeline", f"must be a PipelineConfig, got {type(pipeline).__name__}")
        if not 0 <= refinements <= 5:
            raise InputError("refinements", f"must be in [0, 5], got {refinements}")
        self.pipeline = pipeline
        self.actuator = actuator
        self.refinements = refinements
        self.seed = seed

    def _residuals(self, windows: Sequence[Window], estimates: Mapping[str, float], effects: EffectSet) -> list:
        return [
            residuals(w.signals, simulate_like(w, estimates, effects), w.sample_rate_hz, self.actuator) for w in windows
        ]

    def _block_length(self, found: Sequence[Residuals], rate_hz: float, effect: str | None = None) -> int:
        """The longest integrated autocorrelation time over channels of the residual left by the base
        model (plus ``effect``, at its best fit), at least the smoothing kernel, at most 1/20 of a window."""
        n = min(int(r.mask.sum()) for r in found)
        samples = make_blocks(found, 1, self.actuator)
        chosen = [] if effect is None else [best_choice(samples, [], BY_NAME[effect], self.actuator)[0]]
        residual = fit_model(samples, chosen).residual
        tau = max(integrated_time(residual[c][samples.window == 0], n // 4) for c in residual)
        kernel = 2 * round(DEFAULT_DERIVATIVE_WINDOW_S * rate_hz / 2) + 1
        return int(np.clip(np.ceil(tau), kernel, n // MAX_BLOCK_FRACTION))

    def fit(self, windows: Sequence[Window], truth: Mapping[str, float] | None = None) -> Calibrator:
        if not windows:
            raise InputError("windows", "at least one window is needed")
        started = time.perf_counter()
        before = combined_estimates([estimate_window(w, self.pipeline) for w in windows])
        found = self._residuals(windows, before, EffectSet())
        # Two passes: the effective sample size is judged on what the leading candidate leaves, since
        # the base model's residual still holds the effect's own (slow) structure.
        rate = windows[0].sample_rate_hz
        leader = scores(make_blocks(found, self._block_length(found, rate), self.actuator), [], self.actuator)[0]
        length = self._block_length(found, rate, leader[0].candidate.effect)
        blocks = make_blocks(found, length, self.actuator)
        null = fit_model(blocks, [])
        ranked = scores(blocks, [], self.actuator)
        candidates = [self._describe(choice, result, null) for choice, result in ranked]
        selected, checks = self._select(blocks, ranked, null, windows, before)
        effects = EffectSet()
        structure = structure_left(blocks, [] if selected is None else [selected])
        after, found_after = before, found
        if selected is not None:
            effects, after, found_after = self._add_effect(windows, selected, _parameters(selected, ranked), length)
        self.report_ = self._report(
            windows, before, after, found, found_after, candidates, selected, checks, structure, blocks, truth
        )
        self.report_["effects"] = effects.as_dict()
        self.report_["timings_s"] = {"total": time.perf_counter() - started}
        self.residuals_before_, self.residuals_after_ = found, found_after
        return self

    def _add_effect(
        self, windows: Sequence[Window], selected: Choice, parameters: dict[str, float], length: int
    ) -> tuple[EffectSet, dict[str, float], list[Residuals]]:
        """Switch the effect on, re-estimate, and refine its parameters on what is still left.

        The first fit was made against estimates the missing effect had biased; each round refits
        the same signature to the new residual and corrects the parameters by it.
        """
        name = selected.candidate.effect
        for round_ in range(self.refinements + 1):
            effects = EffectSet({name: parameters})
            after = combined_estimates([estimate_window(w, self.pipeline, effects=effects) for w in windows])
            found_after = self._residuals(windows, after, effects)
            if round_ == self.refinements:
                break
            blocks = make_blocks(found_after, length, self.actuator)
            choice = Choice(
                selected.candidate,
                selected.grid,
                candidate_columns(blocks, selected.candidate, selected.grid, self.actuator),
            )
            increment = selected.candidate.parameters(fit_model(blocks, [choice]).coefficients[name], selected.grid)
            update = refined(name, parameters, increment)
            if not within_bounds(name, update):
                break  # a correction past the effect's bounds is not trusted: keep the last good model
            parameters = update
        self.refined_parameters_ = parameters
        return effects, after, found_after

    def _describe(self, choice: Choice, result, null) -> dict[str, Any]:
        effect = choice.candidate.effect
        parameters = choice.candidate.parameters(result.coefficients[effect], choice.grid)
        channel = PRIMARY.get(effect, "torque")
        return {
            "effect": effect,
            "parameters": parameters,
            "rms_reduction": float(1.0 - np.sqrt(result.rss[channel] / max(null.rss[channel], 1e-300))),
            "score": float(null.bic - result.bic),  # BIC gain on the effective sample: > 10 is strong evidence
            "plausible": within_bounds(effect, parameters),
        }

    def _tie_break(
        self, windows: Sequence[Window], estimates: Mapping[str, float], options: list[tuple[Choice, Any]]
    ) -> tuple[Choice, dict[str, float]]:
        """Candidates with one trace in the residuals: simulate each and keep the one whose motor speed
        matches the windows best (a torque constant also changes the back-EMF, hence the top speed;
        a current-sensor gain does not)."""
        speed_rms = {}
        for choice, result in options:
            effect = choice.candidate.effect
            effects = EffectSet({effect: choice.candidate.parameters(result.coefficients[effect], choice.grid)})
            found = self._residuals(windows, estimates, effects)
            speed_rms[effect] = float(np.sqrt(np.mean([r.rms_report["motor_speed"] ** 2 for r in found])))
        best = min(options, key=lambda option: speed_rms[option[0].candidate.effect])
        return best[0], speed_rms

    def _select(
        self, blocks: Blocks, ranked, null, windows: Sequence[Window], estimates: Mapping[str, float]
    ) -> tuple[Choice | None, dict[str, Any]]:
        """The best candidate if it passes all three bars; the checks either way."""
        checks: dict[str, Any] = {"indistinguishable_from": []}
        for choice, result in ranked:
            parameters = choice.candidate.parameters(result.coefficients[choice.candidate.effect], choice.grid)
            if null.bic - result.bic <= MIN_BIC_GAIN:
                checks["reason"] = "no candidate lowers the BIC by more than 10: the residual is noise"
                return None, checks
            if not within_bounds(choice.candidate.effect, parameters):
                continue  # a fit the effect cannot physically have: try the next
            checks["held_out_gain"] = held_out_gain(blocks, [], choice)
            checks["stability"] = stability(blocks, [], choice.candidate.effect, self.actuator, self.seed)
            checks["indistinguishable_from"] = [
                c.candidate.effect for c, r in ranked if c is not choice and r.bic - result.bic < SAME_SIGNATURE_BIC
            ]
            rivals = [
                (c.candidate.effect, r.bic - result.bic)
                for c, r in ranked
                if c is not choice
                and SAME_SIGNATURE_BIC <= r.bic - result.bic < MIN_BIC_GAIN
                and within_bounds(
                    c.candidate.effect, c.candidate.parameters(r.coefficients[c.candidate.effect], c.grid)
                )
            ]
            if rivals:
                rival, gap = rivals[0]
                checks["contenders"] = [choice.candidate.effect, rival]
                checks["reason"] = (
                    f"{choice.candidate.effect} and {rival} explain the residual about equally (BIC gap {gap:.1f} < "
                    f"{MIN_BIC_GAIN:g}): neither is named"
                )
                return None, checks
            if checks["held_out_gain"] < HELD_OUT_GAIN:
                checks["reason"] = f"{choice.candidate.effect} does not predict held-out blocks"
                return None, checks
            if checks["stability"] < MIN_STABILITY:
                checks["reason"] = f"{choice.candidate.effect} is chosen in only {checks['stability']:.0%} of resamples"
                return None, checks
            checks["reason"] = "strong evidence, predicts held-out blocks, stable under resampling"
            twins = [
                (c, r)
                for c, r in ranked
                if c.candidate.effect in checks["indistinguishable_from"]
                and within_bounds(
                    c.candidate.effect, c.candidate.parameters(r.coefficients[c.candidate.effect], c.grid)
                )
            ]
            if twins:
                group = {choice.candidate.effect, *checks["indistinguishable_from"]}
                choice, speed_rms = self._tie_break(windows, estimates, [(choice, result), *twins])
                checks["tie_break_speed_rms"] = speed_rms
                checks["indistinguishable_from"] = sorted(group - {choice.candidate.effect})
                checks["reason"] += f"; told from its twin by the motor speed it predicts ({choice.candidate.effect})"
            return choice, checks
        checks["reason"] = "every candidate that fits needs implausible parameters"
        return None, checks

    def _report(
        self, windows, before, after, found, found_after, candidates, selected, checks, structure, blocks, truth
    ):
        def rms(found_list: Sequence[Residuals]) -> dict[str, float]:
            keys = found_list[0].rms_report
            return {k: float(np.sqrt(np.mean([r.rms_report[k] ** 2 for r in found_list]))) for k in keys}

        strongest = max(structure, key=lambda name: structure[name])
        unexplained = None
        contenders = checks.get("contenders")
        if contenders:
            variable = FOLLOWS[contenders[0]]
            described = (
                f"the residual follows {variable}; {' and '.join(contenders)} both fit it, "
                "and these windows cannot tell which"
            )
            unexplained = {"variable": variable, "bic_gain": structure.get(variable), "description": described}
        elif structure[strongest] > MIN_BIC_GAIN:
            described = f"the residual torque varies systematically with {strongest}, and no candidate explains it"
            unexplained = {"variable": strongest, "bic_gain": structure[strongest], "description": described}
        report: dict[str, Any] = {
            "schema": SCHEMA,
            "n_windows": len(windows),
            "residual_rms_before": rms(found),
            "residual_rms_after": rms(found_after),
            "candidates": candidates,
            "selected_effect": None if selected is None else selected.candidate.effect,
            "selected_parameters": None if selected is None else self.refined_parameters_,
            "selection": {**checks, "block_length_samples": blocks.length, "effective_samples": blocks.n},
            "unexplained_structure": unexplained,
            "estimates_before": before,
            "estimates_after": after,
        }
        if truth is not None:
            for when, values in (("before", before), ("after", after)):
                report[f"error_{when}"] = {k: abs(values[k] - float(truth[k])) for k in TARGETS}
                report[f"error_pct_{when}"] = {k: 100 * abs(values[k] / float(truth[k]) - 1) for k in TARGETS}
        return report


def _parameters(selected: Choice, ranked) -> dict[str, float]:
    result = next(r for c, r in ranked if c is selected)
    return selected.candidate.parameters(result.coefficients[selected.candidate.effect], selected.grid)
