"""A geared servo window's own dataset: its set point run in closed loop (``ema.kinds.geared.loop``) at health drawn
around the physics reading, each run logged as the window was.

FDJ, η_O and η_A are drawn in a box centred on the output-error reading, ±``SPAN_SIGMAS`` of its std wide but never
narrower than ``MIN_HALF`` (a share of FDJ, a step of η), filled by a scrambled Halton sequence. Each simulated
position is read through the encoder's step at a phase of its own, and carries the window's own misfit (what the
window holds beyond its simulation at the reading) at a random shift and sign: the model misses part of every real
run, and a network that never saw such a miss would read it as a change of health; the held-out runs, which carry
it too, say what it costs. The network's inputs are the position's error to the set point, averaged into
``n_timesteps`` bins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.simulate.design import SPAN_SIGMAS, binned, halton, shifted_copies
from ema.kinds.geared.log_reading import HEALTH, GearedPrepared
from ema.kinds.geared.loop import simulate_lanes
from ema.kinds.geared.output_error import HealthReading

MIN_HALF = {"fdj_nm": 0.1, "eta_o": 0.05, "eta_a": 0.05}  # FDJ relative to its reading, η absolute
PHYSICAL = {"eta_o": (0.1, 0.999), "eta_a": (-0.99, 0.999)}  # where an efficiency is drawn at all
MISFIT_SEED_OFFSET = 7919  # the misfit's shifts and signs: a stream of their own


@dataclass(frozen=True)
class GearedData:
    low: np.ndarray  # (3,) the box, in ``HEALTH`` order
    high: np.ndarray
    truth: np.ndarray  # (S, 3) each simulation's health
    position_rad: np.ndarray  # (S, N) each as logged: through the encoder's step, the window's misfit carried
    inputs: np.ndarray  # (S, F) the network's
    window_inputs: np.ndarray  # (F,)
    targets: tuple[str, ...] = HEALTH

    def normalize(self, values: np.ndarray) -> np.ndarray:
        return (values - self.low) / (self.high - self.low)

    def denormalize(self, unit: np.ndarray) -> np.ndarray:
        return self.low + unit * (self.high - self.low)


def box(reading: HealthReading) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of FDJ, η_O and η_A: the reading ±max(``SPAN_SIGMAS`` stds, ``MIN_HALF``), narrowed (never moved)
    to stay inside what is physical: a box centred on the reading, so that the physics solution's pull towards the
    nominal (``ema.kinds.geared.output_error``) averages out over it rather than reading as a bias."""
    centre = np.array([reading.values[name] for name in HEALTH])
    scale = np.array([abs(centre[0]), 1.0, 1.0])
    wide = np.array(
        [max(SPAN_SIGMAS * reading.stds[name], MIN_HALF[name] * s, 1e-6) for name, s in zip(HEALTH, scale, strict=True)]
    )
    floor = np.array([1e-3 * abs(centre[0]), PHYSICAL["eta_o"][0], PHYSICAL["eta_a"][0]])
    ceiling = np.array([np.inf, PHYSICAL["eta_o"][1], PHYSICAL["eta_a"][1]])
    inside = np.clip(centre, floor + 1e-6, ceiling - 1e-6)
    half = np.maximum(np.minimum(wide, np.minimum(inside - floor, ceiling - inside)), 1e-6)
    return inside - half, inside + half


def read_through(position: np.ndarray, step: float, phase: np.ndarray) -> np.ndarray:
    """(S, N) positions as an encoder of ``step`` reads them, each row at its own ``phase`` of the step."""
    if step <= 0:
        return position
    return step * (np.round(position / step + phase[:, None]) - phase[:, None])


def simulate_geared_dataset(prepared: GearedPrepared, reading: HealthReading, config: PipelineConfig) -> GearedData:
    """The window's ``config.total_simulations`` closed-loop runs, their health and the network's inputs."""
    low, high = box(reading)
    count = config.total_simulations
    truth = low + halton(count, config.seed, len(HEALTH)) * (high - low)
    lanes = np.stack([prepared.lane(dict(zip(HEALTH, row, strict=True))) for row in truth])
    simulated = simulate_lanes(prepared.run, lanes).position_rad
    phases = np.random.default_rng(config.seed).uniform(size=count)
    logged = read_through(simulated, prepared.resolution_rad, phases)
    logged = logged + shifted_copies(reading.error_rad, count, config.seed + MISFIT_SEED_OFFSET)
    set_point = prepared.window.signals["set_point_rad"]
    bins = min(config.n_timesteps, len(set_point) // 2)
    inputs = binned(logged - set_point, bins)
    window_inputs = binned(prepared.position_rad - set_point, bins)
    return GearedData(low, high, truth, logged, inputs, window_inputs)
