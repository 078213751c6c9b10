"""A fleet wearing in flight hours, logged as ``benchmarks.foreign_history`` reads it: each actuator's true
health against the hours (linear, speeding up, none; a heavier rotor; a current sensor whose zero changes
by flight) and its windows, drawn by ``tests.foreign``."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from benchmarks.foreign_groups import FAMILIES
from ema.model.actuator import ActuatorDocument
from tests.foreign.windows import Draw, Effects, Health, draw

FIRST_SEED = 200_000  # apart from every other benchmark's and the tests'
SPAN_H = 1000.0  # flight hours the history covers
KINDS = (  # (share of windows, duration [s], log rates [Hz], family or None for any)
    (0.5, 0.5, (10_000.0,), None),
    (0.2, 0.1, (10_000.0,), "gust"),
    (0.2, 0.5, (1_000.0, 2_000.0), None),
    (0.1, 2.0, (10_000.0,), "cruise"),
)
COLD_SHARE = 0.3


@dataclass(frozen=True)
class Thresholds:
    """Where an actuator's life ends, resolved from its document (``ActuatorDocument.threshold``)."""

    fdj_above_nm: float
    eta_o_below: float

    @classmethod
    def of(cls, actuator: ActuatorDocument) -> Thresholds:
        return cls(actuator.threshold("FDJ")[0], actuator.threshold("eta_O")[0])


@dataclass(frozen=True)
class Wear:
    """An actuator's true health against flight hours: from its start to its thresholds as (h / h*)^power
    (1: linear; 2: wear that speeds up; h* infinite: none)."""

    fdj_start_nm: float
    fdj_crossing_h: float
    eta_o_start: float
    eta_o_crossing_h: float
    power: float = 1.0
    inertia_factor: float = 1.0  # its rotor's J_M over the document's, unlogged (it stays with the build)
    zeroed_per_flight: bool = False  # its current sensor keeps a zero off by 0.04–0.2 A, new each flight

    def health(self, hours: float, thresholds: Thresholds) -> Health:
        fdj_share, eta_o_share = ((hours / h) ** self.power for h in (self.fdj_crossing_h, self.eta_o_crossing_h))
        fdj = self.fdj_start_nm + (thresholds.fdj_above_nm - self.fdj_start_nm) * fdj_share
        eta_o = self.eta_o_start + (thresholds.eta_o_below - self.eta_o_start) * eta_o_share
        return Health(fdj_nm=fdj, fsj_nm=2.0 * fdj, eta_o=eta_o)


KINDS_OF_WEAR = ("linear", "speeding up", "healthy", "linear, heavier rotor", "linear, zero off by flight")
WINDOWS_PER_FLIGHT = 3  # of an actuator whose sensor's zero changes by flight, 0.3 h apart


def wear(actuator: int, kind: str = "linear") -> Wear:
    """A wearing actuator's (``KINDS_OF_WEAR``), or a healthy one's (the same start, no wear)."""
    rng = np.random.default_rng(FIRST_SEED + actuator)
    fdj, fdj_h, eta_o, eta_o_h = (
        rng.uniform(0.045, 0.055),
        SPAN_H * rng.uniform(1.5, 4.0),
        rng.uniform(0.85, 0.95),
        SPAN_H * rng.uniform(1.5, 4.0),
    )
    if kind == "healthy":
        return Wear(fdj, math.inf, eta_o, math.inf)
    inertia = float(rng.uniform(1.03, 1.1)) if kind == "linear, heavier rotor" else 1.0
    power = 2.0 if kind == "speeding up" else 1.0
    return Wear(fdj, fdj_h, eta_o, eta_o_h, power, inertia, zeroed_per_flight=kind == "linear, zero off by flight")


def flights(actuator: int, truth: Wear, n_windows: int) -> tuple[np.ndarray, list[str | None], np.ndarray]:
    """The actuator's windows: flight hours, flight_id and the current sensor's offset [A] of each. Most
    actuators log one window a flight (their sensors on zero); one whose zero changes by flight logs
    ``WINDOWS_PER_FLIGHT``, its offset drawn per flight."""
    rng = np.random.default_rng(FIRST_SEED + actuator)
    if not truth.zeroed_per_flight:
        return np.sort(rng.uniform(0, SPAN_H, n_windows)), [None] * n_windows, np.zeros(n_windows)
    n_flights = n_windows // WINDOWS_PER_FLIGHT
    starts = np.repeat(np.sort(rng.uniform(0, SPAN_H, n_flights)), WINDOWS_PER_FLIGHT)
    hours = starts + np.tile(0.3 * np.arange(WINDOWS_PER_FLIGHT), n_flights)
    flight = np.repeat(np.arange(n_flights), WINDOWS_PER_FLIGHT)
    offsets = rng.choice([-1.0, 1.0], n_flights) * rng.uniform(0.04, 0.2, n_flights)
    return hours, [f"flight-{k}" for k in flight], offsets[flight]


def logged_window(
    actuator: int, j: int, hours: float, truth: Wear, thresholds: Thresholds, offset_a: float = 0.0
) -> Draw:
    """Window ``j`` of the actuator's history, at ``hours``: a kind of ``KINDS``, cold or not, its current
    sensor ``offset_a`` off zero."""
    seed = FIRST_SEED + 1000 * (actuator + 1) + j
    rng = np.random.default_rng(seed)
    _, duration, rates, family = KINDS[rng.choice(len(KINDS), p=[k[0] for k in KINDS])]
    cold = rng.uniform() < COLD_SHARE
    viscous = float(rng.uniform(1.2, 2.0)) if cold else 1.0
    health, effects = (
        truth.health(hours, thresholds),
        Effects(viscous_factor=viscous, inertia_factor=truth.inertia_factor, current_bias_a=offset_a),
    )
    drawn = draw(
        seed,
        family or FAMILIES[j % 5],
        health=health,
        effects=effects,
        duration_s=duration,
        sample_rate_hz=float(rng.choice(rates)),
    )
    drawn.document.update(actuator_id=f"foreign/history-{actuator}", window_id=f"w{j:03d}", flight_hours=hours)
    return drawn
