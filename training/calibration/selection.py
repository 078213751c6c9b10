"""Which effect explains the residual: forward selection of effect groups, judged on independent blocks.

Residuals are strongly time-correlated (a 2 ms smoothing kernel, and the model error itself),
so plain BIC on n samples sees structure in noise. Every channel is averaged over blocks as long
as its integrated autocorrelation time; block means are then nearly independent, and their count
is the effective sample size the BIC uses. An effect group enters only if it lowers the BIC by
more than ``MIN_BIC_GAIN`` (strong evidence), predicts held-out blocks better than the model
without it, and is chosen again in most bootstrap resamples of the blocks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from sim.params import ActuatorParams
from training.calibration.channels import CHANNELS, Residuals
from training.calibration.library import CANDIDATES, Candidate, nuisance

MIN_BIC_GAIN = 10.0
HELD_OUT_GAIN = 0.05  # held-out RSS must drop by at least 5 %
BOOTSTRAP_RESAMPLES = 40
MIN_STABILITY = 0.7
STRUCTURE_BINS = 8
STRUCTURE_VARIABLES = ("speed_radps", "position_rad", "load_nm", "current_a", "time_s")


def integrated_time(values: np.ndarray, max_lag: int) -> float:
    """1 + 2·Σρ_k up to the first negative autocorrelation (Geyer's initial positive sequence)."""
    x = values - values.mean()
    variance = float(x @ x)
    if variance == 0.0:
        return 1.0
    tau = 1.0
    for lag in range(1, max_lag):
        rho = float(x[:-lag] @ x[lag:]) / variance
        if rho <= 0:
            break
        tau += 2 * rho
    return tau


@dataclass
class Blocks:
    """Block means of every window's channels, nuisance columns and variables, stacked."""

    length: int
    y: dict[str, np.ndarray]  # channel -> (n_blocks,)
    nuisance: dict[str, np.ndarray]  # channel -> (n_blocks, k): per-window copies, block-diagonal
    variables: dict[str, np.ndarray]
    window: np.ndarray  # (n_blocks,) index of the window each block comes from
    _raw: list[tuple[Residuals, np.ndarray]] = field(repr=False, default_factory=list)

    @property
    def n(self) -> int:
        return len(self.window)


def _block_means(values: np.ndarray, length: int) -> np.ndarray:
    count = len(values) // length
    return values[: count * length].reshape(count, length, *values.shape[1:]).mean(axis=1)


def make_blocks(windows: Sequence[Residuals], length: int, actuator: ActuatorParams) -> Blocks:
    ys: dict[str, list[np.ndarray]] = {c: [] for c in CHANNELS}
    nuis: dict[str, list[np.ndarray]] = {c: [] for c in CHANNELS}
    variables: dict[str, list[np.ndarray]] = {}
    index = []
    raw = []
    for w, r in enumerate(windows):
        columns = nuisance(r.variables, actuator)
        for channel in CHANNELS:
            ys[channel].append(_block_means(r.channels[channel][r.mask], length))
            nuis[channel].append(_block_means(columns[channel][r.mask], length))
        for name, values in r.variables.items():
            variables.setdefault(name, []).append(_block_means(values[r.mask], length))
        index.append(np.full(len(ys["torque"][-1]), w))
        raw.append((r, r.mask))
    n_windows = len(windows)

    def block_diagonal(parts: list[np.ndarray]) -> np.ndarray:
        k = parts[0].shape[1]
        out = np.zeros((sum(len(p) for p in parts), k * n_windows))
        row = 0
        for w, part in enumerate(parts):
            out[row : row + len(part), w * k : (w + 1) * k] = part
            row += len(part)
        return out

    return Blocks(
        length=length,
        y={c: np.concatenate(v) for c, v in ys.items()},
        nuisance={c: block_diagonal(v) for c, v in nuis.items()},
        variables={k: np.concatenate(v) for k, v in variables.items()},
        window=np.concatenate(index),
        _raw=raw,
    )


def candidate_columns(blocks: Blocks, candidate: Candidate, grid: float, actuator: ActuatorParams) -> dict:
    """The candidate's block-mean columns per channel (shared coefficients across windows)."""
    parts: dict[str, list[np.ndarray]] = {}
    for residual, mask in blocks._raw:
        for channel, columns in candidate.columns(residual.variables, grid, actuator).items():
            parts.setdefault(channel, []).append(_block_means(columns[mask], blocks.length))
    return {channel: np.concatenate(p) for channel, p in parts.items()}


@dataclass(frozen=True)
class Choice:
    candidate: Candidate
    grid: float
    columns: dict  # channel -> (n_blocks, k)

    @property
    def n_columns(self) -> int:
        return sum(c.shape[1] for c in self.columns.values()) + (0 if np.isnan(self.grid) else 1)


@dataclass
class Fit:
    bic: float
    rss: dict[str, float]
    coefficients: dict[str, dict[str, np.ndarray]]  # effect -> channel -> coefficients
    residual: dict[str, np.ndarray]


def fit_model(blocks: Blocks, choices: Sequence[Choice], rows: np.ndarray | None = None) -> Fit:
    """Least squares per channel of nuisance + chosen effects; BIC on the blocks used."""
    rows = np.arange(blocks.n) if rows is None else rows
    bic, rss, residual = 0.0, {}, {}
    coefficients: dict[str, dict[str, np.ndarray]] = {c.candidate.effect: {} for c in choices}
    k_total = sum(choice.n_columns for choice in choices)
    for channel in CHANNELS:
        y = blocks.y[channel][rows]
        parts = [blocks.nuisance[channel][rows]] + [c.columns[channel][rows] for c in choices if channel in c.columns]
        design = np.concatenate(parts, axis=1)
        k_total += blocks.nuisance[channel].shape[1]
        beta = np.linalg.lstsq(design, y, rcond=None)[0] if design.shape[1] else np.zeros(0)
        residual[channel] = y - design @ beta
        rss[channel] = float(residual[channel] @ residual[channel])
        bic += len(y) * np.log(max(rss[channel], 1e-300) / len(y))
        start = blocks.nuisance[channel].shape[1]
        for choice in choices:
            if channel in choice.columns:
                width = choice.columns[channel].shape[1]
                coefficients[choice.candidate.effect][channel] = beta[start : start + width]
                start += width
    return Fit(bic + k_total * np.log(len(rows)), rss, coefficients, residual)


def best_choice(
    blocks: Blocks, chosen: Sequence[Choice], candidate: Candidate, actuator: ActuatorParams, rows=None
) -> tuple[Choice, Fit]:
    """The candidate at its best grid value (lowest BIC), given what is already chosen."""
    best: tuple[Choice, Fit] | None = None
    for grid in candidate.grid:
        choice = Choice(candidate, grid, candidate_columns(blocks, candidate, grid, actuator))
        result = fit_model(blocks, [*chosen, choice], rows)
        if best is None or result.bic < best[1].bic:
            best = (choice, result)
    assert best is not None
    return best


def scores(
    blocks: Blocks, chosen: Sequence[Choice], actuator: ActuatorParams, candidates=CANDIDATES, rows=None
) -> list[tuple[Choice, Fit]]:
    """Every candidate not yet chosen, at its best grid value, best BIC first."""
    taken = {c.candidate.effect for c in chosen}
    ranked = [best_choice(blocks, chosen, c, actuator, rows) for c in candidates if c.effect not in taken]
    return sorted(ranked, key=lambda pair: pair[1].bic)


def held_out_gain(blocks: Blocks, chosen: Sequence[Choice], choice: Choice) -> float:
    """Relative drop of held-out RSS (2-fold, alternate blocks) when ``choice`` joins.

    Alternate blocks rather than halves: both folds then see every regime of the window (a signature
    like viscous friction is told from FDJ only in the few accelerations), and blocks as long as
    the correlation time keep the folds nearly independent.
    """
    fold = np.arange(blocks.n) % 2
    gains = []
    for held in (0, 1):
        train, test = np.flatnonzero(fold != held), np.flatnonzero(fold == held)
        # Channels weighed in their own noise units, the same for both models.
        null_rss = fit_model(blocks, list(chosen), train).rss
        totals = []
        for model in (list(chosen), [*chosen, choice]):
            rss = 0.0
            for channel in CHANNELS:
                parts = [blocks.nuisance[channel]] + [c.columns[channel] for c in model if channel in c.columns]
                design = np.concatenate(parts, axis=1)
                beta = np.linalg.lstsq(design[train], blocks.y[channel][train], rcond=None)[0]
                error = blocks.y[channel][test] - design[test] @ beta
                rss += float(error @ error) / max(null_rss[channel] / len(train), 1e-300)
            totals.append(rss)
        gains.append(1.0 - totals[1] / totals[0])
    return float(np.mean(gains))


def stability(blocks: Blocks, chosen: Sequence[Choice], effect: str, actuator: ActuatorParams, seed: int) -> float:
    """Share of bootstrap resamples of the blocks in which ``effect`` again ranks first and passes the BIC bar."""
    rng = np.random.default_rng(seed)
    hits = 0
    for _ in range(BOOTSTRAP_RESAMPLES):
        rows = rng.integers(0, blocks.n, blocks.n)
        base = fit_model(blocks, chosen, rows).bic
        ranked = [(c, fit_model(blocks, [*chosen, c], rows)) for c in _fixed_choices(blocks, chosen, actuator)]
        top, result = min(ranked, key=lambda pair: pair[1].bic)
        hits += top.candidate.effect == effect and result.bic < base - MIN_BIC_GAIN
    return hits / BOOTSTRAP_RESAMPLES


def _fixed_choices(blocks: Blocks, chosen: Sequence[Choice], actuator: ActuatorParams) -> list[Choice]:
    """Each remaining candidate at its full-data best grid value (re-searching the grid per resample
    would only add the grid's look-elsewhere freedom, which the BIC already charges)."""
    return [choice for choice, _ in scores(blocks, chosen, actuator)]


def structure_left(blocks: Blocks, chosen: Sequence[Choice]) -> dict[str, float]:
    """BIC gain of a piecewise-constant function of each variable on the torque residual; > MIN_BIC_GAIN = structure."""
    final = fit_model(blocks, chosen)
    residual = final.residual["torque"]
    n = len(residual)
    null = n * np.log(max(float(residual @ residual), 1e-300) / n)
    gains = {}
    for name in STRUCTURE_VARIABLES:
        values = blocks.variables[name]
        edges = np.quantile(values, np.linspace(0, 1, STRUCTURE_BINS + 1)[1:-1])
        bins = np.digitize(values, edges)
        means = np.array([residual[bins == b].mean() if np.any(bins == b) else 0.0 for b in range(STRUCTURE_BINS)])
        rest = residual - means[bins]
        bic = n * np.log(max(float(rest @ rest), 1e-300) / n) + (STRUCTURE_BINS - 1) * np.log(n)
        gains[name] = float(null - bic)
    return gains
