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
from training.calibration.library import BY_NAME, PRIMARY, refined, within_bounds
from training.calibration.report import calibration_report
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
        max_effects: int = 2,
        seed: int = 0,
    ) -> None:
        if not isinstance(pipeline, PipelineConfig):
            raise InputError("pipeline", f"must be a PipelineConfig, got {type(pipeline).__name__}")
        if not 0 <= refinements <= 5:
            raise InputError("refinements", f"must be in [0, 5], got {refinements}")
        if not 1 <= max_effects <= 4:
            raise InputError("max_effects", f"must be in [1, 4], got {max_effects}")
        self.max_effects = max_effects
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
        chosen, steps = self._forward(blocks, ranked, null, windows, before)
        structure = structure_left(blocks, chosen)
        effects, after, found_after = EffectSet(), before, found
        if chosen:
            effects, after, found_after = self._add_effects(windows, chosen, blocks)
        self.report_ = calibration_report(
            windows, (before, after), (found, found_after), candidates, chosen, steps, structure, blocks, truth
        )
        self.report_["effects"] = effects.as_dict()  # every effect added, refined parameters
        self.report_["selected_parameters"] = effects.as_dict()[chosen[0].candidate.effect] if chosen else None
        self.report_["timings_s"] = {"total": time.perf_counter() - started}
        self.residuals_before_, self.residuals_after_ = found, found_after
        return self

    def _forward(
        self, blocks: Blocks, ranked, null, windows: Sequence[Window], estimates: Mapping[str, float]
    ) -> tuple[list[Choice], list[dict[str, Any]]]:
        """Forward selection of effect groups: add the best candidate while one passes every bar."""
        chosen: list[Choice] = []
        steps: list[dict[str, Any]] = []
        current = null
        while len(chosen) < self.max_effects:
            choice, checks = self._select(blocks, ranked, current, chosen, windows, estimates)
            steps.append({**checks, "selected": None if choice is None else choice.candidate.effect})
            if choice is None:
                break
            chosen.append(choice)
            current = fit_model(blocks, chosen)
            ranked = scores(blocks, chosen, self.actuator)
        return chosen, steps

    def _add_effects(
        self, windows: Sequence[Window], chosen: Sequence[Choice], blocks: Blocks
    ) -> tuple[EffectSet, dict[str, float], list[Residuals]]:
        """Switch the effects on, re-estimate, and refine their parameters on what is still left.

        The first fit was made against estimates the missing effects had biased; each round refits
        the same signatures to the new residual and corrects the parameters by them.
        """
        parameters = _parameters_of(chosen, fit_model(blocks, chosen))
        for round_ in range(self.refinements + 1):
            effects = EffectSet(parameters)
            after = combined_estimates([estimate_window(w, self.pipeline, effects=effects) for w in windows])
            found_after = self._residuals(windows, after, effects)
            if round_ == self.refinements:
                break
            left = make_blocks(found_after, blocks.length, self.actuator)
            again = [_rebuild(c, left, self.actuator) for c in chosen]
            increments = _parameters_of(again, fit_model(left, again))
            update = {name: refined(name, parameters[name], increments[name]) for name in parameters}
            if not all(within_bounds(name, values) for name, values in update.items()):
                break  # a correction past an effect's bounds is not trusted: keep the last good model
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
        self,
        windows: Sequence[Window],
        estimates: Mapping[str, float],
        chosen: Sequence[Choice],
        options: list[tuple[Choice, Any]],
    ) -> tuple[Choice, dict[str, float]]:
        """Candidates with one trace in the residuals: simulate each and keep the one whose motor speed
        matches the windows best (a torque constant also changes the back-EMF, hence the top speed;
        a current-sensor gain does not)."""
        speed_rms = {}
        for choice, result in options:
            effects = EffectSet(_parameters_of([*chosen, choice], result))
            found = self._residuals(windows, estimates, effects)
            speed_rms[choice.candidate.effect] = float(
                np.sqrt(np.mean([r.rms_report["motor_speed"] ** 2 for r in found]))
            )
        best = min(options, key=lambda option: speed_rms[option[0].candidate.effect])
        return best[0], speed_rms

    def _select(
        self,
        blocks: Blocks,
        ranked,
        current,
        chosen: Sequence[Choice],
        windows: Sequence[Window],
        estimates: Mapping[str, float],
    ) -> tuple[Choice | None, dict[str, Any]]:
        """The best candidate beyond ``chosen`` if it passes every bar; the checks either way."""
        checks: dict[str, Any] = {"indistinguishable_from": []}
        none_left = "no further candidate" if chosen else "no candidate"
        for choice, result in ranked:
            if current.bic - result.bic <= MIN_BIC_GAIN:
                checks["reason"] = f"{none_left} lowers the BIC by more than {MIN_BIC_GAIN:g}: the rest is noise"
                return None, checks
            if not _plausible(choice, result):
                continue  # a fit the effect cannot physically have: try the next
            effect = choice.candidate.effect
            gaps = [(c, r, r.bic - result.bic) for c, r in ranked if c is not choice and _plausible(c, r)]
            twins = [(c, r) for c, r, gap in gaps if gap < SAME_SIGNATURE_BIC]
            rivals = [(c.candidate.effect, gap) for c, r, gap in gaps if SAME_SIGNATURE_BIC <= gap < MIN_BIC_GAIN]
            checks["indistinguishable_from"] = [c.candidate.effect for c, _ in twins]
            if rivals:
                rival, gap = rivals[0]
                checks["contenders"] = [effect, rival]
                checks["reason"] = (
                    f"{effect} and {rival} explain the residual about equally "
                    f"(BIC gap {gap:.1f} < {MIN_BIC_GAIN:g}): neither is named"
                )
                return None, checks
            # Only now the costly checks (the bootstrap refits every candidate 40 times): a close rival
            # already rules the name out.
            checks["held_out_gain"] = held_out_gain(blocks, chosen, choice)
            checks["stability"] = stability(blocks, chosen, effect, self.actuator, self.seed)
            if checks["held_out_gain"] < HELD_OUT_GAIN:
                checks["reason"] = f"{effect} does not predict held-out blocks"
                return None, checks
            if checks["stability"] < MIN_STABILITY:
                checks["reason"] = f"{effect} is chosen in only {checks['stability']:.0%} of resamples"
                return None, checks
            checks["reason"] = "strong evidence, predicts held-out blocks, stable under resampling"
            if twins:
                group = {effect, *checks["indistinguishable_from"]}
                choice, speed_rms = self._tie_break(windows, estimates, chosen, [(choice, result), *twins])
                checks["tie_break_speed_rms"] = speed_rms
                checks["indistinguishable_from"] = sorted(group - {choice.candidate.effect})
                checks["reason"] += f"; told from its twin by the motor speed it predicts ({choice.candidate.effect})"
            return choice, checks
        checks["reason"] = "every candidate that fits needs implausible parameters"
        return None, checks


def _plausible(choice: Choice, fitted) -> bool:
    effect = choice.candidate.effect
    return within_bounds(effect, choice.candidate.parameters(fitted.coefficients[effect], choice.grid))


def _parameters_of(choices: Sequence[Choice], fitted) -> dict[str, dict[str, float]]:
    """Each chosen effect's parameters from a joint fit."""
    return {
        c.candidate.effect: c.candidate.parameters(fitted.coefficients[c.candidate.effect], c.grid) for c in choices
    }


def _rebuild(choice: Choice, blocks: Blocks, actuator: ActuatorParams) -> Choice:
    """The same candidate and grid value, its columns recomputed on other blocks."""
    return Choice(choice.candidate, choice.grid, candidate_columns(blocks, choice.candidate, choice.grid, actuator))
