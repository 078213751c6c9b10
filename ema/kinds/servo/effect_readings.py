"""What each load effect reads of a servo's logs: the stacked problem (``ema.kinds.servo.stacked_solve``) with the
effect at the grid value that predicts the held-out folds best, and whether the logs hold evidence for it (its
constants physical, every fold predicted better, the held-out residual cut by ``MIN_HELD_OUT_DROP``).

The calibration names effects from these readings (with its noise-only copies' z besides). An estimate whose log the
model misses reads them too: which effect is missing its one log cannot tell, but each one it holds evidence for
moves the constants, and the stds must hold every such reading (``widened``), as the rotary's calibration widens
its stds where effects it cannot choose between read apart. A model's miss then costs the answer its precision,
not its truth: two runs of one machine, which excite the missing effect differently, read within their stds.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ema.estimate.assess.weighing import Assessed
from ema.estimate.documents import Note
from ema.kinds.servo.inverse import UNITS
from ema.kinds.servo.load_effects import ServoEffect, looked_for
from ema.kinds.servo.log_reading import ServoPrepared
from ema.kinds.servo.stacked_solve import Solved, problem, solved

MIN_HELD_OUT_DROP = 0.05  # of the held-out residual sum of squares
HELD_READINGS = 2.0  # the stds widened until this many of them hold each reading


@dataclass(frozen=True)
class Reading:
    """One effect read on the logs, against the model without it (``base``)."""

    effect: ServoEffect
    value: float  # its nonlinear constant at the best grid value
    solution: Solved
    drop: float  # fractional drop of the held-out residual
    every_fold: bool  # each fold predicted better
    plausible: bool  # its constants physical

    @property
    def held(self) -> bool:
        """The logs hold evidence for it (module docstring)."""
        return self.plausible and self.every_fold and self.drop >= MIN_HELD_OUT_DROP


def best_of(effect: ServoEffect, prepared: Sequence[ServoPrepared], model: dict[str, float]) -> tuple[float, Solved]:
    """The effect at the candidate constant (``ServoEffect.candidates``) that predicts the held-out folds best."""
    values = effect.candidates(prepared[0].servo)
    trials = [(value, solved(problem(prepared, {**model, effect.name: value}))) for value in values]
    return min(trials, key=lambda trial: float(trial[1].held_out_rss.sum()))


def reading(effect: ServoEffect, prepared: Sequence[ServoPrepared], model: dict[str, float], base: Solved) -> Reading:
    """``effect`` read on the logs on top of ``model`` (``base``: its solution without the effect)."""
    value, solution = best_of(effect, prepared, model)
    return Reading(
        effect,
        value,
        solution,
        float(1.0 - solution.held_out_rss.sum() / base.held_out_rss.sum()),
        bool(np.all(solution.held_out_rss < base.held_out_rss)),
        effect.plausible(solution.values),
    )


def held_readings(prepared: ServoPrepared, left_out: np.ndarray) -> tuple[Solved, list[Reading]]:
    """The window's solution with its document's effects (less the ``left_out`` rows), and each further effect's
    reading the window holds evidence for."""
    window = [replace(prepared, disturbed=left_out)]
    model = dict(prepared.effects)
    base = solved(problem(window, model))
    found = [reading(effect, window, model, base) for effect in looked_for(prepared.servo, model)]
    return base, [r for r in found if r.held]


def widened(answer: Assessed, base: Solved, readings: Sequence[Reading]) -> tuple[Assessed, Note | None]:
    """``answer`` with each constant's std widened until ±``HELD_READINGS`` stds hold what every held reading moves
    it by (the constant as the reading solves it, less the base solution's), and a note naming the effects."""
    if not readings:
        return answer, None
    stds = dict(answer.stds)
    for name in stds:
        moved = [abs(r.solution.values[name] - base.values[name]) for r in readings if name in r.solution.values]
        stds[name] = float(np.hypot(stds[name], max(moved, default=0.0) / HELD_READINGS))
    fdj = "fdj_n"
    read = ", ".join(f"{r.effect.name} {r.solution.values[fdj]:.4g}" for r in readings if fdj in r.solution.values)
    note = Note(
        code="model_form",
        parameter="FDJ",
        text=f"the model misses part of this log, and it holds evidence for effects the document lacks; read with "
        f"each, FDJ moves from {base.values[fdj]:.4g} to {read} {UNITS[fdj]}: the stds are widened until ±"
        f"{HELD_READINGS:g} std holds every reading (FDJ's {answer.stds[fdj]:.3g} -> {stds[fdj]:.3g} {UNITS[fdj]}); "
        "ema calibrate on the logs tells which effect it is",
    )
    return replace(answer, stds=stds), note
