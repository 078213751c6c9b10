"""One model of a geared servo solved on many of its runs at once, and scored on runs it did not see.

Every run is simulated from its own set point at one set of constants (``ema.kinds.geared.effects``: a model frees
some, the rest stay at their neutral values); the constants are solved so that the simulated positions follow the
logged ones, every ``DECIMATE``-th sample of every run at once (robust least squares, as a window's health is read,
``ema.kinds.geared.output_error``). A held-out score solves the model on four folds of the runs and simulates the
fifth, in turn: the mean absolute position error [rad] on runs a solution never saw.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ema.calibration.limits import FOLDS
from ema.kinds.geared.duty_gain import LoggedDuty
from ema.kinds.geared.effects import CONSTANTS, bounds, diff_steps
from ema.kinds.geared.loop import LANE_PARAMETERS, Packed, Run, pack, simulate_packed
from ema.kinds.geared.output_error import DIFF_STEP, LOSS_SCALE_RAD, correlation_inflation

DECIMATE = 3  # every third sample of a run in a solve: its neighbours add little but time
MAX_EVALUATIONS = 400  # a solve from afar; one warm-started from a neighbour's answer stops long before


@dataclass(frozen=True)
class LoggedRun:
    """A run as its calibration reads it: what the simulator takes, the logged position (N,) and duty (N,)."""

    window_id: str
    run: Run
    position_rad: np.ndarray
    duty_ratio: np.ndarray

    @property
    def logged_duty(self) -> LoggedDuty:
        r = self.run
        return LoggedDuty(self.duty_ratio, r.set_point_rad, self.position_rad, r.motor_on, r.position_gain, r.step_s)


@dataclass(frozen=True)
class Solved:
    values: dict[str, float]  # every constant of ``CONSTANTS`` (the free ones solved)
    stds: dict[str, float]  # the free ones' Gauss–Newton stds, the residual's correlation counted
    free: tuple[str, ...]
    cost: float = 0.0  # the solve's robust loss at its answer (what ``best_of`` compares)


def lane(values: Mapping[str, float]) -> np.ndarray:
    """The simulator's lane (``LANE_PARAMETERS``) of a model's constants."""
    return np.array([values[name] for name in LANE_PARAMETERS])


@dataclass(frozen=True)
class RunSet:
    """Runs packed for the simulator (``ema.kinds.geared.loop.Packed``), their logged positions end to end (T,) and
    the samples a solve reads (every ``DECIMATE``-th of each run)."""

    runs: tuple[LoggedRun, ...]
    packed: Packed
    logged: np.ndarray
    solved_samples: np.ndarray

    @classmethod
    def of(cls, runs: Sequence[LoggedRun]) -> RunSet:
        packed = pack([r.run for r in runs])
        kept = np.concatenate(
            [np.arange(a, z, DECIMATE) for a, z in zip(packed.starts[:-1], packed.starts[1:], strict=True)]
        )
        return cls(tuple(runs), packed, np.concatenate([r.position_rad for r in runs]), kept)

    def simulated(self, values: Mapping[str, float]) -> np.ndarray:
        """(T,) every run's positions at ``values``, end to end."""
        return simulate_packed(self.packed, lane(values))

    def errors(self, values: Mapping[str, float]) -> np.ndarray:
        """(R,) each run's mean absolute position error [rad] at ``values``."""
        return np.array([np.mean(np.abs(e)) for e in self.packed.split(self.logged - self.simulated(values))])


def positions(runs: Sequence[LoggedRun], values: Mapping[str, float]) -> list[np.ndarray]:
    """Each run simulated at ``values``: its positions (N_i,)."""
    run_set = RunSet.of(runs)
    return run_set.packed.split(run_set.simulated(values))


def errors(runs: Sequence[LoggedRun], values: Mapping[str, float]) -> np.ndarray:
    """(R,) each run's mean absolute position error [rad] at ``values``."""
    return RunSet.of(runs).errors(values)


def _residual(run_set: RunSet, start: Mapping[str, float], free: tuple[str, ...]) -> Callable[..., np.ndarray]:
    def residual(x: np.ndarray) -> np.ndarray:
        values = {**start, **dict(zip(free, x, strict=True))}
        return (run_set.logged - run_set.simulated(values))[run_set.solved_samples]

    return residual


def solve(runs: Sequence[LoggedRun], free: tuple[str, ...], start: Mapping[str, float], *, stds: bool = True) -> Solved:
    """``free`` of ``CONSTANTS`` solved on ``runs`` from ``start`` (every constant's value), the rest held there."""
    low, high = bounds(free)
    x0 = np.clip([start[name] for name in free], low, high)
    run_set = RunSet.of(runs)
    residual = _residual(run_set, start, free)
    solution = least_squares(
        residual,
        x0,
        bounds=(low, high),
        loss="soft_l1",
        f_scale=LOSS_SCALE_RAD,
        diff_step=diff_steps(free, DIFF_STEP),
        x_scale="jac",
        max_nfev=MAX_EVALUATIONS,
    )
    values = {**start, **dict(zip(free, map(float, solution.x), strict=True))}
    return Solved(values, _stds(solution.jac, residual(solution.x), free) if stds else {}, free, float(solution.cost))


def best_of(runs: Sequence[LoggedRun], free: tuple[str, ...], starts: Sequence[Mapping[str, float]]) -> Solved:
    """The model solved from each of ``starts``, the one whose answer fits the runs best: a friction read as
    sliding (FDJ) or as viscous (C) leaves the runs about as well near either, and a solve from one side stays
    there."""
    return min((solve(runs, free, start, stds=False) for start in starts), key=lambda solved: solved.cost)


def _stds(jacobian: np.ndarray, error: np.ndarray, free: tuple[str, ...]) -> dict[str, float]:
    n, p = jacobian.shape
    variance = float(error @ error) / max(n - p, 1) * correlation_inflation(error)
    covariance = np.linalg.pinv(jacobian.T @ jacobian) * variance
    return dict(zip(free, map(float, np.sqrt(np.clip(np.diag(covariance), 0.0, None))), strict=True))


def folds_of(runs: Sequence[LoggedRun]) -> np.ndarray:
    """(R,) each run's fold: the runs in the order of their ids dealt out in turn, whatever order they came in."""
    order = sorted(range(len(runs)), key=lambda i: runs[i].window_id)
    fold = np.empty(len(runs), dtype=np.int64)
    fold[order] = np.arange(len(runs)) % FOLDS
    return fold


@dataclass(frozen=True)
class HeldOut:
    errors_rad: np.ndarray  # (R,) each run's mean |position error| simulated by the solution that never saw it
    solutions: list[Solved]  # one a fold

    @property
    def score(self) -> float:
        return float(np.mean(self.errors_rad))

    def fold_scores(self, folds: np.ndarray) -> np.ndarray:
        return np.array([self.errors_rad[folds == k].mean() for k in range(FOLDS)])


def held_out(runs: Sequence[LoggedRun], free: tuple[str, ...], start: Mapping[str, float]) -> HeldOut:
    """The model ``free`` solved on four folds, each fifth simulated by it (warm-started from ``start``)."""
    folds = folds_of(runs)
    held = np.empty(len(runs))
    solutions = []
    for k in range(FOLDS):
        seen = [r for r, f in zip(runs, folds, strict=True) if f != k]
        unseen = [r for r, f in zip(runs, folds, strict=True) if f == k]
        solved = solve(seen, free, start, stds=False)
        held[folds == k] = errors(unseen, solved.values)
        solutions.append(solved)
    return HeldOut(held, solutions)


def fold_spread(solutions: list[Solved], names: Sequence[str]) -> dict[str, float]:
    """The grouped jackknife's std of each constant over fold solutions: (k−1)/k · Σ(θ_i − θ̄)², the runs'
    own scatter (and the model's misfit) in it, which a Gauss–Newton std on them all does not see."""
    k = len(solutions)
    spread = {}
    for name in names:
        values = np.array([s.values[name] for s in solutions])
        spread[name] = float(np.sqrt((k - 1) / k * np.sum((values - values.mean()) ** 2)))
    return spread


__all__ = ["CONSTANTS", "HeldOut", "LoggedRun", "Solved", "errors", "held_out", "solve"]
