"""Window -> Case-1B dataset: simulations of that very command, preprocessed as the window is, in a box
around the physics estimate (``simulate_dataset``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sim.aircraft import FlightCondition, Load, LoggedLoad
from sim.batch import BatchResult, InitialState, simulate_batch
from sim.commands import knots_from_samples
from sim.effects import EffectSet
from sim.noise import SensorNoise, add_sensor_noise
from sim.params import ActuatorParams, HealthParams
from sim.residual import residual_torque_nm, smoothed
from sim.window import Window
from training import design
from training.baseline import FitSettings, FrictionFit, regressors
from training.config import PipelineConfig
from training.noise_level import excess_noise
from training.preprocess import as_read, sliding_features

INITIAL_FIT_SAMPLES = 8
# All the estimators read, and so all drawn with the window's noise (position too: the hinge
# moment is read along it, sim.hinge, and b·0.01° ≈ 0.1 N·m).
SIGNALS_READ = ("current_a", "motor_speed_radps", "hinge_moment_nm", "position_deg")


@dataclass(frozen=True)
class Scenario:
    """What every simulation of a dataset shares: the command, the load, the start, the rate."""

    command_knots_deg: np.ndarray  # (n_samples + 1,) one command (Case 1) or (n_sims, n_samples + 1) (Case 2)
    load: Load = field(default_factory=FlightCondition)
    initial: InitialState = field(default_factory=InitialState)
    sample_rate_hz: float = 10_000.0
    effects: EffectSet = field(default_factory=EffectSet)

    @property
    def n_samples(self) -> int:
        return self.command_knots_deg.shape[-1] - 1

    def simulate(self, health: HealthParams, lanes: int | None = None) -> BatchResult:
        return simulate_batch(
            self.command_knots_deg, health, self.load, self.initial, self.sample_rate_hz, self.effects, lanes=lanes
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
        motor_speed_radps=float(np.clip(at_zero(window.signals["motor_speed_radps"]), -700.0, 700.0)),
        current_a=float(np.clip(at_zero(window.signals["current_a"]), -30.0, 30.0)),
    )


def logged_load(window: Window) -> LoggedLoad:
    """The window's own hinge moment (smoothed of sensor noise) as the load its simulations feel."""
    rate = window.sample_rate_hz
    return LoggedLoad(
        window.flight_condition,
        smoothed(window.signals["hinge_moment_nm"], rate),
        smoothed(window.signals["position_deg"], rate),
    )


def scenario_from_window(window: Window, effects: EffectSet = EffectSet()) -> Scenario:
    """Case 1B for a logged window: its command, its logged load, its first state."""
    return Scenario(
        command_knots_deg=knots_from_samples(window.signals["command_deg"])[0],
        load=logged_load(window),
        initial=initial_state(window),
        sample_rate_hz=window.sample_rate_hz,
        effects=effects,
    )


@dataclass(frozen=True)
class Simulated:
    """A batch of noisy simulated windows and what the estimators read of them."""

    health: HealthParams  # the truth of every simulation (FSJ included)
    noise: SensorNoise  # the window's own sensor noise, added to every simulation
    signals: dict[str, np.ndarray]  # SIGNALS_READ, (n, n_samples), sensor noise added, then as_read
    residual_nm: np.ndarray  # (n, n_samples) T_R of the noisy signals
    clean_residual_nm: np.ndarray  # (k, n_samples) T_R without sensor noise, of the last k: the noise floor's reference


def simulate_noisy(
    scenario: Scenario, health: HealthParams, window: Window, reference: HealthParams, seed: int, clean_last: int
) -> Simulated:
    """Simulate ``health``, add the window's own noise to what the estimators read, read it as the window
    is read (``as_read``) and reconstruct T_R (and without noise for the last ``clean_last`` simulations).

    The noise is measured against a clean simulation of the window at ``reference`` (one point),
    run in the same batch: it takes a lane the batch would have padded anyway.
    """
    together = HealthParams(
        *(np.concatenate([getattr(health, name), getattr(reference, name)]) for name in ("fsj_nm", "fdj_nm", "eta_o"))
    )
    result = scenario.simulate(together)
    rate = scenario.sample_rate_hz
    noise = excess_noise(window.signals, {name: values[-1] for name, values in result.signals.items()}, rate)
    clean = {name: result.signals[name][:-1] for name in SIGNALS_READ}
    rng = np.random.default_rng(seed)
    noisy = add_sensor_noise(clean, noise, rng, rate)

    def residual(s: dict[str, np.ndarray]) -> np.ndarray:
        return residual_torque_nm(s["current_a"], s["motor_speed_radps"], s["hinge_moment_nm"], rate)

    seen = as_read(noisy, rate)
    tail = as_read({name: values[len(health) - clean_last :] for name, values in clean.items()}, rate)
    return Simulated(health, noise, seen, residual(seen), residual(tail))


def window_noise(window: Window, scenario: Scenario, health: HealthParams) -> SensorNoise:
    """The window's sensor noise, measured against a clean simulation of its own command at ``health``."""
    clean = scenario.simulate(health, lanes=1).simulation(0)
    return excess_noise(window.signals, clean, window.sample_rate_hz)


@dataclass(frozen=True)
class Data:
    """Everything simulated for one window."""

    scenario: Scenario
    box: design.Box
    noise: SensorNoise
    sims: Simulated  # n_simulations for training, then check_windows held out
    sliding: np.ndarray  # (n_samples,) the window's Eq. 5.1 samples
    inputs: np.ndarray  # (n_total, n_timesteps) network inputs of every simulation
    window_inputs: np.ndarray  # (1, n_timesteps)
    actuator: ActuatorParams  # as the window is read (``Prepared.actuator``: J_M and C as it shows them)


def simulate_dataset(
    window: Window,
    seen: Window,
    physics: FrictionFit,
    config: PipelineConfig,
    actuator: ActuatorParams,
    effects: EffectSet,
) -> Data:
    """The box around the physics estimate, the window's sensor noise (measured on ``window`` as logged),
    the simulations (the spec's model with ``effects``: the window's viscous coefficient), and the features
    of both (the window read as ``seen``: through ``as_read``, its T_R with ``actuator``)."""
    box = design.box_around(physics.fdj_nm[0], physics.fdj_std_nm[0], physics.eta_o[0], physics.eta_o_std[0])
    scenario = scenario_from_window(seen, effects)
    health = design.draw(box, config.total_simulations, config.seed)
    sims = simulate_noisy(scenario, health, window, design.centre(box), config.seed + 1, config.check_windows)
    rate = window.sample_rate_hz
    residual = residual_torque_nm(
        seen.signals["current_a"], seen.signals["motor_speed_radps"], seen.signals["hinge_moment_nm"], rate, actuator
    )
    sliding = regressors(seen.signals, rate, actuator, FitSettings(), residual_nm=residual)[3][0]
    n_timesteps = min(config.n_timesteps, window.n_samples)
    inputs = sliding_features(sims.residual_nm, sliding, n_timesteps)
    features = sliding_features(residual, sliding, n_timesteps)
    return Data(scenario, box, sims.noise, sims, sliding, inputs, features, actuator)
