"""Twins: effects that leave the same trace in the residual torque, told apart by simulation.

A torque constant g and a current-sensor gain s both leave a term in k_T·I in the residual
torque; only the first also changes the back-EMF (k_e = k_T), hence how much voltage is left to
drive current near top speed, hence how the motor speed and current evolve. Each twin is added
to the simulator in turn, the window simulated at the estimates, and the one whose speed and
current stay closer to the measured ones (in units of their noise) is named; the other is
reported as indistinguishable when the difference is small.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from calibration.selection import Evidence
from sim.noise import SensorNoise
from sim.window import Window
from training.dataset import scenario_from_window
from training.design import inside
from training.reproduction import SETTLE_S

TWINS = {"torque_constant": "current_sensor_gain", "current_sensor_gain": "torque_constant"}
CLEAR_MARGIN = 0.05  # the loser's output error at least 5 % above the winner's: a clear call


def output_error(
    windows: Sequence[Window], estimates: Mapping[str, float], option: Evidence, noise: Sequence[SensorNoise]
) -> float:
    """Mean over windows of RMS(speed)/σ_speed + RMS(current)/σ_current, simulated with ``option`` added."""
    effects = option.family.term(option.beta, option.grid)
    if effects is None:
        return float("inf")  # a gain outside what the simulator admits: not this twin
    health = inside(estimates["FDJ"], estimates["eta_O"])
    total = 0.0
    for window, level in zip(windows, noise, strict=True):
        simulated = scenario_from_window(window, effects).simulate(health, lanes=1).simulation(0)
        keep = slice(round(SETTLE_S * window.sample_rate_hz), None)
        for name, sigma in (("motor_speed_radps", level.motor_speed_radps), ("current_a", level.current_a)):
            error = window.signals[name][keep] - simulated[name][keep]
            total += float(np.sqrt(np.mean(error**2))) / max(sigma, 1e-9)
    return total / len(windows)


def tell_apart(
    windows: Sequence[Window],
    estimates: Mapping[str, float],
    options: Sequence[Evidence],
    noise: Sequence[SensorNoise],
) -> tuple[Evidence, dict[str, float], bool]:
    """The twin whose simulation follows the windows best, each one's output error, and whether the call is clear."""
    errors = {o.family.name: output_error(windows, estimates, o, noise) for o in options}
    ranked = sorted(options, key=lambda o: errors[o.family.name])
    best, runner = errors[ranked[0].family.name], errors[ranked[1].family.name]
    return ranked[0], errors, runner > (1 + CLEAR_MARGIN) * best
