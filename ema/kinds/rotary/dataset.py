"""Window -> Case-1B dataset: simulations of that very command, preprocessed as the window is, in a box
around the physics estimate (``simulate_dataset``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.kinds.rotary.box import Box, box_around, centre, draw
from ema.kinds.rotary.physics.features import as_read, sliding_features
from ema.kinds.rotary.physics.friction import FrictionSolution, SolveSettings, regressors
from ema.kinds.rotary.physics.noise_reading import excess_noise
from ema.kinds.rotary.physics.scenario import Scenario, scenario_from_window
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.simulator.residual import residual_torque_nm
from ema.kinds.rotary.simulator.sensor_noise import add_seeded_noise
from ema.model.actuator import RotaryActuator
from ema.model.noise import SensorNoise
from ema.model.params import DriveConstants, HealthParams
from ema.model.window import RotaryWindow

# All the estimators read, and so all drawn with the window's noise (position too: the hinge
# moment is read along it, ema.kinds.rotary.simulator.hinge, and b·0.01° ≈ 0.1 N·m).
SIGNALS_READ = ("current_a", "motor_speed_radps", "hinge_moment_nm", "position_deg")


@dataclass(frozen=True)
class Simulated:
    """A batch of noisy simulated windows and what the estimators read of them."""

    health: HealthParams  # the truth of every simulation (FSJ included)
    noise: SensorNoise  # the window's own sensor noise, added to every simulation
    signals: dict[str, np.ndarray]  # SIGNALS_READ, (n, n_samples), sensor noise added, then as_read
    residual_nm: np.ndarray  # (n, n_samples) T_R of the noisy signals
    clean_residual_nm: np.ndarray  # (k, n_samples) T_R without sensor noise, of the last k: the noise floor's reference
    reference: HealthParams  # the one point simulated clean to measure the noise against
    reference_signals: dict[str, np.ndarray]  # its five signals, as simulated (no noise, not read)


def simulate_noisy(
    scenario: Scenario, health: HealthParams, window: RotaryWindow, reference: HealthParams, seed: int, clean_last: int
) -> Simulated:
    """Simulate ``health``, add the window's own noise to what the estimators read, read it as the window
    is read (``as_read``) and reconstruct T_R (and without noise for the last ``clean_last`` simulations).

    The noise is measured against a clean simulation of the window at ``reference`` (one point),
    run in the same batch: it takes a lane the batch would have padded anyway. Its signals are kept: where
    the answer is that point, the answer's check needs no simulation of its own.
    """
    together = HealthParams(
        *(np.concatenate([getattr(health, name), getattr(reference, name)]) for name in ("fsj_nm", "fdj_nm", "eta_o"))
    )
    result = scenario.simulate(together, reuse_output=True)  # nothing below keeps a view of it
    rate = scenario.sample_rate_hz
    at_reference = {name: values[-1].copy() for name, values in result.signals.items()}
    noise = excess_noise(window.signals, at_reference, rate)
    clean = {name: result.signals[name][:-1] for name in SIGNALS_READ}
    noisy = add_seeded_noise(clean, noise, seed, rate)

    def residual(s: dict[str, np.ndarray]) -> np.ndarray:
        return residual_torque_nm(s["current_a"], s["motor_speed_radps"], s["hinge_moment_nm"], rate, scenario.drive)

    seen = as_read(noisy, rate)
    tail = as_read({name: values[len(health) - clean_last :] for name, values in clean.items()}, rate)
    return Simulated(health, noise, seen, residual(seen), residual(tail), reference, at_reference)


@dataclass(frozen=True)
class Data:
    """Everything simulated for one window."""

    scenario: Scenario
    box: Box
    noise: SensorNoise
    sims: Simulated  # n_simulations for training, then check_simulations held out
    sliding: np.ndarray  # (n_samples,) the window's Eq. 5.1 samples
    inputs: np.ndarray  # (n_total, n_timesteps) network inputs of every simulation
    window_inputs: np.ndarray  # (1, n_timesteps)
    drive_as_read: DriveConstants  # as the window is read (``Prepared.drive_as_read``: J_M and C as it shows them)


def simulate_dataset(
    window: RotaryWindow,
    seen: RotaryWindow,
    physics: FrictionSolution,
    config: PipelineConfig,
    *,
    document: RotaryActuator,
    drive: DriveConstants,
    effects: EffectSet,
) -> Data:
    """The box around the physics estimate, the window's sensor noise (measured on ``window`` as logged),
    the simulations (the ``document``'s drive with ``effects``: the window's viscous coefficient), and the
    features of both (the window read as ``seen``: through ``as_read``, its T_R with ``drive``, the
    document's drive with J_M and C as the window shows them)."""
    fdj, eta_o = physics.fdj_nm[0], physics.eta_o[0]
    box = box_around(fdj, physics.fdj_std_nm[0], eta_o, physics.eta_o_std[0], document.health.fdj)
    scenario = scenario_from_window(seen, document.params, document.hinge, effects)
    health = draw(box, config.total_simulations, config.seed)
    sims = simulate_noisy(scenario, health, window, centre(box), config.seed + 1, config.check_simulations)
    rate = window.sample_rate_hz
    residual = residual_torque_nm(
        seen.signals["current_a"], seen.signals["motor_speed_radps"], seen.signals["hinge_moment_nm"], rate, drive
    )
    sliding = regressors(seen.signals, rate, drive, SolveSettings(), residual_nm=residual)[3][0]
    n_timesteps = min(config.n_timesteps, window.n_samples)
    inputs = sliding_features(sims.residual_nm, sliding, n_timesteps)
    features = sliding_features(residual, sliding, n_timesteps)
    return Data(scenario, box, sims.noise, sims, sliding, inputs, features, drive)
