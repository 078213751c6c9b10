"""Does the model, at the estimates, reproduce the measured window? The output-error check.

The window is simulated once more, clean, at the final estimates, from its own command, logged
load and first state; each signal's RMS difference to the measurement (after the first
``SETTLE_S``, while the simulation settles from an estimated state) is divided by the floor that
sensor noise alone would leave: the estimated noise of that signal, and for the residual torque
the RMS difference between noisy and clean reconstructions of the held-out simulations. A ratio
near 1 means the model reproduces the window; a ratio of several means it does not, and the
result says so. Position, speed and current also carry timing differences a model may have
without any bias in friction (they are reported, and only the residual torque decides).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ema.estimate.stats import rms
from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.scenario import SETTLE_S, Scenario
from ema.kinds.rotary.simulator.residual import residual_torque_nm
from ema.model.noise import SensorNoise
from ema.model.params import DriveConstants, HealthParams
from ema.model.window import RotaryWindow


def output_error_ratios(
    window: RotaryWindow,
    scenario: Scenario,
    health: HealthParams,
    *,
    noise: SensorNoise,
    residual_floor_nm: float,
    sliding: np.ndarray,
    drive: DriveConstants,
    simulated_at_health: Mapping[str, np.ndarray] | None = None,
) -> dict[str, float]:
    """Per signal, RMS(measured − simulated at ``health``) over its noise-only floor; the measured T_R
    reconstructed with ``drive`` (as the window is read), the simulated with the drive it is drawn with.
    ``simulated_at_health``: the scenario's clean simulation at ``health`` where one was run already."""
    rate = window.sample_rate_hz
    if simulated_at_health is None:
        simulated_at_health = scenario.simulate(health, lanes=1).simulation(0)
    simulated = as_read(simulated_at_health, rate)
    measured = window.signals
    keep = np.arange(window.n_samples) >= round(SETTLE_S * rate)
    floors = {
        "position_deg": noise.position_deg,
        "motor_speed_radps": noise.motor_speed_radps,
        "current_a": noise.current_a,
    }
    ratios = {
        name: rms(measured[name][keep] - simulated[name][keep]) / max(floor, 1e-12) for name, floor in floors.items()
    }
    torque = _residual(measured, rate, drive) - _residual(simulated, rate, scenario.drive)
    ratios["residual_torque"] = rms(torque[keep & sliding]) / max(residual_floor_nm, 1e-12)
    return ratios


def _residual(signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants) -> np.ndarray:
    current, speed, hinge = signals["current_a"], signals["motor_speed_radps"], signals["hinge_moment_nm"]
    return residual_torque_nm(current, speed, hinge, rate, drive)
