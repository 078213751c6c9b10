"""A servo calibration's two measures of a solution over every window at once: the stacked inverse problem solved
(Eq. 5.1 in the load frame on each window's decimated force, Newey–West stds, each fold predicted by the others)
and what noise alone leaves in it (each window simulated in closed loop at the solved constants, its sensor read
at ``COPIES`` phases of its step), from which the rows a force the log lacks disturbs are told; and the solved
constants as the simulator takes them (``simulator_frame``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ema.calibration.held_out import score
from ema.calibration.limits import FOLDS
from ema.estimate.least_squares import coefficients, newey_west_std
from ema.estimate.stats import rms
from ema.kinds.servo.inverse import (
    decimated_problem,
    disturbed_rows,
    inverse_columns,
    load_motion,
    solve_inverse,
)
from ema.kinds.servo.log_reading import ServoPrepared
from ema.kinds.servo.loop_dataset import LANE_COLUMNS, lane_parameters

COPIES = 8
FRAME_PHASES = 4  # phases of the sensor's step the twins of simulator_frame are read at


@dataclass(frozen=True)
class Problem:
    """Every window's decimated force and columns, stacked, and each row's fold."""

    y: np.ndarray
    x: dict[str, np.ndarray]
    fold: np.ndarray
    window: np.ndarray  # each row's window

    def design(self, names: Sequence[str]) -> np.ndarray:
        return np.column_stack([self.x[name] for name in names])


def problem(prepared: Sequence[ServoPrepared], model: dict[str, float]) -> Problem:
    """The stacked problem of ``model`` (effect name -> its nonlinear constant) over the windows."""
    ys, xs, folds, windows = [], [], [], []
    for i, p in enumerate(prepared):
        y, x = decimated_problem(p.force_n, inverse_columns(p.motion, model), p.motion, p.disturbed)
        xs.append(x)
        ys.append(y)
        folds.append(np.minimum(np.arange(len(y)) * FOLDS // len(y), FOLDS - 1))
        windows.append(np.full(len(y), i))
    names = list(xs[0])
    return Problem(
        np.concatenate(ys),
        {name: np.concatenate([x[name] for x in xs]) for name in names},
        np.concatenate(folds),
        np.concatenate(windows),
    )


@dataclass(frozen=True)
class Solved:
    values: dict[str, float]
    stds: dict[str, float]
    error_pct: float
    held_out_rss: np.ndarray  # (FOLDS,) each fold's residual sum of squares, predicted by the other folds
    residual: np.ndarray


def solved(p: Problem) -> Solved:
    names = list(p.x)
    x = p.design(names)
    beta = coefficients(x, p.y)
    residual = p.y - x @ beta
    stds = newey_west_std(x, residual)
    return Solved(
        dict(zip(names, beta.tolist(), strict=True)),
        dict(zip(names, stds.tolist(), strict=True)),
        float(100.0 * np.linalg.norm(residual) / np.linalg.norm(p.y)),
        score(x, p.y, p.fold, ridge=0.0).fold_rss,  # physical columns the rows tell apart: no ridge
        residual,
    )


@dataclass(frozen=True)
class Copies:
    """What noise alone leaves: each window simulated at the base constants, its sensor read at ``COPIES`` phases."""

    rms: np.ndarray  # (COPIES,) the stacked problem's residual RMS, one per phase
    by_row: list[np.ndarray]  # per window, (COPIES, rows): its copies' residual by decimated row
    twins: list[list[ServoPrepared]]  # per phase, every window as the closed loop logs it: what a candidate is read on


def noise_copies(prepared: Sequence[ServoPrepared], base: Solved, model: dict[str, float]) -> Copies:
    misfits: list[float] = []
    by_row: list[list[np.ndarray]] = [[] for _ in prepared]
    copies = []
    for phase in np.linspace(0.0, 1.0, COPIES, endpoint=False):
        twins = [_simulated(p, base.values, model, phase) for p in prepared]
        copies.append(twins)
        misfits.append(rms(solved(problem(twins, model)).residual))
        for i, twin in enumerate(twins):
            solution = solve_inverse(twin.force_n, inverse_columns(twin.motion, model), twin.motion)
            by_row[i].append(solution.residual_by_row)
    return Copies(np.array(misfits), [np.array(rows) for rows in by_row], copies)


def left_out_alike(copies: Copies, prepared: Sequence[ServoPrepared]) -> list[list[ServoPrepared]]:
    """Each copy's windows with the rows their logs leave out (``undisturbed``) left out too: a candidate is read on
    the copies as on the logs."""
    return [
        [replace(twin, disturbed=p.disturbed) for twin, p in zip(twins, prepared, strict=True)]
        for twins in copies.twins
    ]


def _simulated(p: ServoPrepared, values: dict[str, float], model: dict[str, float], phase: float) -> ServoPrepared:
    """``p`` with its window's position and force as the closed loop at ``values`` logs them."""
    s = p.window.signals
    run = p.closed_loop(lane_parameters(values, model)[None, :], np.array([phase]))
    motion = load_motion(run.position_m[0], p.window.sample_rate_hz, p.bandwidth_hz, p.loop.resolution_m)
    force = (run.drive_force_n[0] - s.get("load_n", 0.0))[motion.samples]
    return replace(p, motion=motion, force_n=force)


def undisturbed(prepared: Sequence[ServoPrepared], copies: Copies, model: dict[str, float]) -> list[ServoPrepared]:
    """Each window with the rows a force its log lacks disturbs (``disturbed_rows``) left out of every solution."""
    out = []
    for p, by_row in zip(prepared, copies.by_row, strict=True):
        solution = solve_inverse(p.force_n, inverse_columns(p.motion, model), p.motion)
        out.append(replace(p, disturbed=disturbed_rows(solution.residual_by_row, by_row)))
    return out


def simulator_frame(
    prepared: Sequence[ServoPrepared], values: dict[str, float], model: dict[str, float]
) -> dict[str, float]:
    """The constants at which the simulator's closed loop, read as the logs were, gives back ``values`` (what Eq.
    5.1 read on the logs): each moved by the solution's own bias there, v + (v − v̂), v̂ the solution of the windows'
    twins simulated at ``values`` (their sensor read at ``FRAME_PHASES`` phases, the logs' rows left out). Eq. 5.1 reads
    a simulated effect through decimation and filters that shrink it (pre-sliding above all): the document keeps
    the simulator's constants, so that an estimate, which reads through the simulator, finds its nominal on the
    logs that taught it. One step: the bias barely moves over it. A constant the simulator has no parameter for
    (an effect along the stroke) is not simulated, so no bias of it is seen: it keeps the solution's value, as an
    estimate reads it; so does one the twins give no finite read of."""
    reads = [
        solved(problem([_simulated(p, values, model, phase) for p in prepared], model)).values
        for phase in np.linspace(0.0, 1.0, FRAME_PHASES, endpoint=False)
    ]
    moved = {name: 2.0 * value - float(np.mean([read[name] for read in reads])) for name, value in values.items()}
    return {
        name: moved[name] if name in LANE_COLUMNS and np.isfinite(moved[name]) else value
        for name, value in values.items()
    }
