"""Window -> Case-1B dataset: simulations of that very command, preprocessed as the window is."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sim.aircraft import FlightCondition, GroundLoad
from sim.batch import BatchResult, InitialState, simulate_batch
from sim.checks import InputError
from sim.commands import knots_from_samples
from sim.effects import EffectSet
from sim.noise import NO_NOISE, SensorNoise, add_sensor_noise
from sim.params import DEFAULT_RANGES, HealthParams, HealthRanges, eta_a_from_eta_o
from sim.window import Window
from training.noise_level import excess_noise
from training.preprocess import INPUT_SETS, SIGNALS_READ, features

INITIAL_FIT_SAMPLES = 8


@dataclass(frozen=True)
class Scenario:
    """What every simulation of a dataset shares: the command, the load, the start, the rate."""

    command_knots_deg: np.ndarray  # (n_samples + 1,) one command (Case 1) or (n_sims, n_samples + 1) (Case 2)
    load: FlightCondition | GroundLoad = field(default_factory=FlightCondition)
    initial: InitialState = field(default_factory=InitialState)
    sample_rate_hz: float = 10_000.0
    effects: EffectSet = field(default_factory=EffectSet)

    @property
    def n_samples(self) -> int:
        return self.command_knots_deg.shape[-1] - 1

    def simulate(self, health: HealthParams) -> BatchResult:
        return simulate_batch(
            self.command_knots_deg, health, self.load, self.initial, self.sample_rate_hz, self.effects
        )


def initial_state(window: Window) -> InitialState:
    """The state at t = 0: a parabola through the first samples (at their interval centres), taken at 0.

    Not the first sample: the fit averages the sensor noise down, and a parabola follows the motor,
    which reaches 60 rad/s within a millisecond from rest, where a line or a mean would lag it.
    """
    n = min(INITIAL_FIT_SAMPLES, window.n_samples)
    centres = np.arange(n) + 0.5

    def at_zero(values: np.ndarray) -> float:
        return float(np.polyfit(centres, values[:n], 2)[-1])

    return InitialState(
        position_deg=float(np.clip(at_zero(window.signals["position_deg"]), -30.0, 30.0)),
        motor_speed_radps=at_zero(window.signals["motor_speed_radps"]),
        current_a=at_zero(window.signals["current_a"]),
    )


def scenario_from_window(window: Window, effects: EffectSet = EffectSet()) -> Scenario:
    """Case 1B for a logged window: its command, its flight condition, its first state."""
    return Scenario(
        command_knots_deg=knots_from_samples(window.signals["command_deg"])[0],
        load=window.flight_condition,
        initial=initial_state(window),
        sample_rate_hz=window.sample_rate_hz,
        effects=effects,
    )


def normalize_targets(health: HealthParams, ranges: HealthRanges) -> np.ndarray:
    """(n, 2): FDJ and η_O mapped to [0, 1] over their ranges."""
    fdj = (health.fdj_nm - ranges.fdj_nm[0]) / (ranges.fdj_nm[1] - ranges.fdj_nm[0])
    eta_o = (health.eta_o - ranges.eta_o[0]) / (ranges.eta_o[1] - ranges.eta_o[0])
    return np.stack([fdj, eta_o], axis=1)


def denormalize_targets(normalized: np.ndarray, ranges: HealthRanges) -> dict[str, np.ndarray]:
    """Parameter values from normalized predictions (n, 2), with η_A by Eq. 3.4."""
    fdj = ranges.fdj_nm[0] + normalized[:, 0] * (ranges.fdj_nm[1] - ranges.fdj_nm[0])
    eta_o = ranges.eta_o[0] + normalized[:, 1] * (ranges.eta_o[1] - ranges.eta_o[0])
    return {"FDJ": fdj, "eta_O": eta_o, "eta_A": eta_a_from_eta_o(eta_o)}


@dataclass(frozen=True)
class DatasetConfig:
    """Sizes of a training set (thesis Table 6.4 explores these)."""

    n_simulations: int = 500
    n_timesteps: int = 1000
    input_set: str = "residual_torque"
    ranges: HealthRanges = field(default_factory=lambda: DEFAULT_RANGES)
    seed: int = 0

    def __post_init__(self) -> None:
        if not 20 <= self.n_simulations <= 20_000:
            raise InputError("n_simulations", f"must be in [20, 20000], got {self.n_simulations}")
        if not 10 <= self.n_timesteps <= 10_000:
            raise InputError("n_timesteps", f"must be in [10, 10000], got {self.n_timesteps}")
        if self.input_set not in INPUT_SETS:
            raise InputError("inputs", f"unknown input set {self.input_set!r}; known: {', '.join(INPUT_SETS)}")


@dataclass(frozen=True)
class Dataset:
    inputs: np.ndarray  # (n_simulations, n_channels · n_timesteps), preprocessed
    targets: np.ndarray  # (n_simulations, 2): FDJ, η_O normalized to [0, 1]
    health: HealthParams  # the truth of every simulation (FSJ included)
    noise: SensorNoise  # the sensor noise added to every simulation
    config: DatasetConfig


def build_dataset(scenario: Scenario, config: DatasetConfig, noise: SensorNoise = NO_NOISE) -> Dataset:
    """Simulate ``config.n_simulations`` health draws of ``scenario``, add ``noise``, preprocess."""
    rng = np.random.default_rng(config.seed)
    health = HealthParams.uniform(config.n_simulations, config.ranges, rng)
    result = scenario.simulate(health)
    # Noise only where the features read: drawing it for the other signals would cost time, not change them.
    signals = add_sensor_noise({name: result.signals[name] for name in SIGNALS_READ}, noise, rng)
    inputs = features(signals, scenario.sample_rate_hz, config.n_timesteps, config.input_set)
    return Dataset(inputs, normalize_targets(health, config.ranges), health, noise, config)


def window_noise(window: Window, scenario: Scenario, ranges: HealthRanges = DEFAULT_RANGES) -> SensorNoise:
    """The window's sensor noise, measured against a clean simulation of its own command."""
    nominal = HealthParams.single(ranges.nominal_fsj_nm, ranges.nominal_fdj_nm, ranges.nominal_eta_o)
    clean = scenario.simulate(nominal).simulation(0)
    return excess_noise(window.signals, clean)
