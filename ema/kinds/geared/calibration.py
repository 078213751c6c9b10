"""A geared servo calibrated on its runs: its constants learned, what a constant friction misses traced to named
effects, the error before and after, and the completed document.

1. **The base model**, a constant friction (FDJ and a viscous C) with the motor, the loop and the servo's inertia,
   is solved on every run at once (``ema.kinds.geared.stacked_fit``).
2. **The efficiency first**: the thesis's load-dependent friction (η_O, η_A) is tried against the base model, then
   **what else the residual shows** (``ema.kinds.geared.effects``), one effect at a time given those named. An
   effect is scored by its held-out drop, the mean absolute position error of runs simulated by a solution that did
   not see them, and named where that drop stands ``NAME_Z`` stds beyond what it buys on noise-only copies of the
   runs (the model's own simulations read through the encoder's step), at most ``MAX_EFFECTS`` (the shared rules,
   ``ema.calibration.limits``).
3. **The constants** of the model with its named effects are solved on every run; each std is the larger of the
   Gauss–Newton one and the spread of the five fold solutions (the runs' own scatter).
4. **Every run answered** with the completed document, as ``ema estimate`` answers it: how far one run's FDJ, η_O
   and η_A scatter about the nominal beyond their own stds (the document's repeatability), and per load (mass ×
   arm) their medians (``ema.kinds.geared.calibration_report``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ema.calibration.documents import Candidate, HeldOut, NoiseFloor, Step
from ema.calibration.limits import MAX_EFFECTS, NAME_Z, noise_z
from ema.kinds.geared.dataset import read_through
from ema.kinds.geared.duty_gain import gain_at
from ema.kinds.geared.effects import EFFECTS, EFFICIENCY, NEUTRAL, free_constants
from ema.kinds.geared.log_reading import load_run, position_step, repaired_supply
from ema.kinds.geared.stacked_fit import HeldOut as ScoredHeldOut
from ema.kinds.geared.stacked_fit import (
    LoggedRun,
    Solved,
    best_of,
    fold_spread,
    folds_of,
    held_out,
    positions,
    solve,
)
from ema.model.geared import Geared
from ema.model.window import GearedWindow

COPY_SEED = 20_250_317  # the copies' encoder phases: their own stream, the same on every rerun


@dataclass(frozen=True)
class Trial:
    """A model tried on the runs: its effects, its held-out score, and where its solves start."""

    effects: tuple[str, ...]
    held: ScoredHeldOut  # on the runs
    copies: ScoredHeldOut  # on the noise-only copies of the model it is tried against
    start: dict[str, float]


def logged_runs(windows: Sequence[GearedWindow], geared: Geared) -> list[LoggedRun]:
    """Each window as its calibration reads it: what its simulation takes, and its logged position."""
    runs = []
    for window in windows:
        supply, _ = repaired_supply(window.signals["supply_v"])
        s = window.signals
        runs.append(LoggedRun(window.window_id, load_run(window, geared, supply), s["position_rad"], s["duty_ratio"]))
    return runs


def starting_values(runs: Sequence[LoggedRun], geared: Geared) -> list[dict[str, float]]:
    """Where the base model's solves start, from physics of the runs themselves: a motor that stalls at three times
    the heaviest load's moment at full duty (b), reaches the fastest logged speed there (k_e), a servo as heavy as
    its median load, the loop's gain read off the logged duty (``ema.kinds.geared.duty_gain``); its friction mostly
    sliding (FDJ a tenth of that moment), or mostly viscous (C a fiftieth of it per rad/s), the two sides a solve
    stays on (``best_of``)."""
    moment = max(r.run.load_moment_nm for r in runs)
    supply = float(np.median([np.median(r.run.supply_v) for r in runs]))
    speed = max(float(np.max(np.abs(np.diff(r.position_rad)))) / r.run.step_s for r in runs)
    b = 3.0 * moment / supply
    sliding = {
        "torque_per_volt": b,
        "back_emf": b * supply / max(speed, 1e-3),
        "inertia_kg_m2": float(np.median([r.run.load_inertia_kg_m2 for r in runs])),
        "error_gain_per_rad": gain_at([r.logged_duty for r in runs], geared.command_delay_s)[0],
        "duty_limit": geared.duty_limit,
        "min_duty": geared.min_duty,
        "fdj_nm": 0.1 * moment,
        "viscous_nm_s_per_rad": 0.005 * moment,
        "k_opp": 0.0,
        "k_aid": 0.0,
        "static_friction_ratio": geared.static_friction_ratio,
        "command_delay_s": geared.command_delay_s,
    }
    return [sliding, {**sliding, "fdj_nm": 0.01 * moment, "viscous_nm_s_per_rad": 0.02 * moment}]


def noise_copies(runs: Sequence[LoggedRun], values: dict[str, float], step: float) -> list[LoggedRun]:
    """Each run as the model at ``values`` would log it: simulated, read through the encoder's ``step`` at a
    phase of its own (``COPY_SEED``): what the runs would show if the model were the whole truth."""
    simulated = positions(runs, values)
    phases = np.random.default_rng(COPY_SEED).uniform(size=len(runs))
    read = [read_through(q[None, :], step, phase[None])[0] for q, phase in zip(simulated, phases, strict=True)]
    return [LoggedRun(r.window_id, r.run, q, r.duty_ratio) for r, q in zip(runs, read, strict=True)]


def tried(
    runs: Sequence[LoggedRun], copies: Sequence[LoggedRun], effects: tuple[str, ...], start: dict[str, float]
) -> Trial:
    """The model with ``effects`` scored held out on the runs, its new constants started off their neutral values
    (a flat start stays flat), and on the copies from their own truth, ``start`` (the model they were drawn from,
    the new constants neutral): what the effect buys where it is absent."""
    begun = {**start}
    for name in effects:
        for constant, value in EFFECTS[name].start.items():
            if start[constant] == NEUTRAL[constant]:
                begun[constant] = value
    free = free_constants(effects)
    solved = solve(runs, free, begun, stds=False)
    return Trial(effects, held_out(runs, free, solved.values), held_out(copies, free, start), solved.values)


def scored(trial: Trial, against: Trial, folds: np.ndarray, effect: str) -> Candidate:
    """``effect`` as a candidate: its held-out drop on the runs against ``against``'s, in stds of its drops on the
    copies' folds (``noise_z``)."""
    drop = 1.0 - trial.held.score / against.held.score
    null = 1.0 - trial.copies.fold_scores(folds) / against.copies.fold_scores(folds)
    z = noise_z(drop, float(np.mean(null)), float(np.std(null, ddof=1)))
    names = EFFECTS[effect].frees
    return Candidate(
        effect=effect,
        follows=EFFECTS[effect].follows,
        named=False,
        parameters={name: trial.start[name] for name in names},
        rms_reduction=drop,
        held_out_drop=drop,
        score=z,
        plausible=True,
    )


def selected(
    runs: Sequence[LoggedRun], base: Trial, step: float, on_stage: Callable[[str], None]
) -> tuple[Trial, list[Candidate], list[Step]]:
    """The model with its named effects: the efficiency tried first, then every effect not yet named, one named a
    round (the efficiency wherever it stands, ``_chosen``), until a round names none or ``MAX_EFFECTS`` are in."""
    folds, current = folds_of(runs), base
    candidates: list[Candidate] = []
    steps: list[Step] = []
    pool: tuple[str, ...] = (EFFICIENCY,)
    while len(current.effects) < MAX_EFFECTS and pool:
        copies, against = noise_copies(runs, current.start, step), current
        if current is not base:  # the model named last round, scored on its own copies
            copies_held = held_out(copies, free_constants(current.effects), current.start)
            against = Trial(current.effects, current.held, copies_held, current.start)
        trials = {}
        for name in pool:
            on_stage(f"trying {name} on {len(runs)} runs (five folds held out) and on their noise-only copies")
            trials[name] = tried(runs, copies, (*current.effects, name), current.start)
        scores = {name: scored(trial, against, folds, name) for name, trial in trials.items()}
        best = _chosen(scores)
        if best is not None:
            scores[best] = scores[best].model_copy(update={"named": True})
            current = trials[best]
        candidates.extend(scores.values())
        steps.append(Step(selected=best, reason=_named(best, scores[best]) if best else _unnamed(scores)))
        if best is None and pool != (EFFICIENCY,):
            break
        pool = tuple(name for name in EFFECTS if name not in current.effects and (best or name != EFFICIENCY))
    return current, candidates, steps


def _chosen(scores: dict[str, Candidate]) -> str | None:
    """The effect a round names: the efficiency where it stands ``NAME_Z`` beyond noise (the thesis's own, what a
    window's health is read with), else the candidate that stands farthest; None where none stands."""
    standing = [name for name, c in scores.items() if c.score >= NAME_Z and c.held_out_drop > 0]
    if EFFICIENCY in standing:
        return EFFICIENCY
    return max(standing, key=lambda name: scores[name].score) if standing else None


def _named(effect: str, candidate: Candidate) -> str:
    return (
        f"{EFFECTS[effect].says}: {candidate.held_out_drop:.1%} less held-out position error, "
        f"z {candidate.score:.0f} against noise-only copies"
    )


def _unnamed(scores: dict[str, Candidate]) -> str:
    if not scores:
        return "no effect left to try"
    said = ", ".join(f"{name} z {c.score:.1f} ({c.held_out_drop:+.1%})" for name, c in scores.items())
    return f"none stands {NAME_Z:g} stds beyond what noise-only copies explain: {said}"


@dataclass(frozen=True)
class LearnedModel:
    """The calibration's model: its final solve with every constant's std (the larger of the Gauss–Newton one and
    the folds' spread), the base and the final trials, what each round scored and named, the noise floor and the
    held-out errors before and after."""

    solved: Solved
    stds: dict[str, float]
    base: Trial
    final: Trial
    candidates: list[Candidate]
    steps: list[Step]
    noise_floor: NoiseFloor
    held: HeldOut


def learned_model(
    windows: Sequence[GearedWindow], geared: Geared, on_stage: Callable[[str], None]
) -> tuple[LearnedModel, list[LoggedRun]]:
    """The selection and the final solve (steps 1 to 3 of the module docstring)."""
    runs = logged_runs(windows, geared)
    step = position_step(np.concatenate([r.position_rad for r in runs]), geared)
    on_stage(f"solving a constant friction's model on {len(runs)} runs")
    start = best_of(runs, free_constants(()), starting_values(runs, geared)).values
    copies = noise_copies(runs, start, step)
    base = Trial((), held_out(runs, free_constants(()), start), held_out(copies, free_constants(()), start), start)
    final, candidates, steps = selected(runs, base, step, on_stage)
    on_stage(f"solving the model with {', '.join(final.effects) or 'no effect'} on every run")
    free = free_constants(final.effects)
    solved = solve(runs, free, final.start)
    spread = fold_spread(final.held.solutions, free)
    stds = {name: max(solved.stds[name], spread[name]) for name in free}
    floor = NoiseFloor(copies=len(runs), equation_error_ratio=base.held.score / max(base.copies.score, 1e-300))
    held = HeldOut(
        rss_before=float(np.sum(base.held.errors_rad**2)),
        rss_after=float(np.sum(final.held.errors_rad**2)),
        adopted=bool(final.effects),
        note=f"mean |position error| of runs simulated by solutions that did not see them: {base.held.score:.4f} "
        f"rad with a constant friction, {final.held.score:.4f} rad with {', '.join(final.effects) or 'nothing named'}",
    )
    return LearnedModel(solved, stds, base, final, candidates, steps, floor, held), runs
