"""Stage 2, noise floor: what the equation error of *these* windows looks like when nothing is missing.

Each window is simulated once, clean, with its own command, logged load and first state at the
estimates the base model gives it; then ``NOISE_COPIES`` independent draws of the window's own
estimated sensor noise are added. Every statistic the selection computes on the measured
windows is computed on each copy too: the copies carry the same trajectory, the same 2 ms
reconstruction and its approximation error, the same correlated noise, and none of the missing
physics. A candidate is evidence only where the measured statistic stands far outside their
spread (no effective-sample-size guess, no BIC on correlated samples).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ema.kinds.rotary.equations import Equations, equations
from ema.kinds.rotary.physics.scenario import inside, scenario_from_window
from ema.kinds.rotary.simulator.sensor_noise import add_sensor_noise
from ema.model import runtime
from ema.model.actuator import RotaryActuator
from ema.model.bounds import NOISE_COPIES
from ema.model.noise import SensorNoise
from ema.model.params import DriveConstants
from ema.model.window import RotaryWindow


def clean_replicas(
    windows: Sequence[RotaryWindow], estimates: Mapping[str, float], actuator: RotaryActuator
) -> list[dict[str, np.ndarray]]:
    """Each window simulated at ``estimates`` (FSJ at twice FDJ), without noise."""
    health = inside(estimates["FDJ"], estimates["eta_O"], actuator.health.fdj)
    return [
        scenario_from_window(w, actuator.params, actuator.hinge).simulate(health, lanes=1).simulation(0)
        for w in windows
    ]


def noise_copies(
    clean: Sequence[dict[str, np.ndarray]],
    noise: Sequence[SensorNoise],
    rate: float,
    orders: Sequence[float],
    seed: int,
    drive: DriveConstants,
    *,
    copies: int = NOISE_COPIES,
    on_copy: Callable[[], None] | None = None,
) -> list[Equations]:
    """``copies`` noisy versions of the clean replicas, each as the selection sees a window set; ``on_copy`` is
    called before each draw (and may raise to stop there). The draws come from one generator in turn; their
    equations, independent, are built on the simulator's threads."""
    rng = np.random.default_rng(seed)
    drawn = []
    for _ in range(copies):
        if on_copy is not None:
            on_copy()
        drawn.append([add_sensor_noise(signals, level, rng, rate) for signals, level in zip(clean, noise, strict=True)])
    return runtime.map_on_pool(lambda noisy: equations(noisy, rate, orders, drive), drawn)
