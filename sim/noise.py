"""Sensor noise: what turns a clean simulation into what a real actuator's sensors would log."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from sim.checks import in_range


@dataclass(frozen=True)
class SensorNoise:
    """White noise standard deviation of each logged signal, per sample at the log rate."""

    position_deg: float = 0.01  # resolver / LVDT [deg]
    motor_speed_radps: float = 0.5  # Hall-sensor speed [rad/s]
    current_a: float = 0.05  # phase-current sensor [A]
    hinge_moment_nm: float = 2.0  # strain gauge or computed load [N·m]
    command_deg: float = 0.0  # the command is a digital signal: exact

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            in_range(f"noise.{name}", value, 0.0, 1e3)

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


NO_NOISE = SensorNoise(0.0, 0.0, 0.0, 0.0, 0.0)


def add_sensor_noise(
    signals: dict[str, np.ndarray], noise: SensorNoise, rng: np.random.Generator
) -> dict[str, np.ndarray]:
    """A copy of ``signals`` with independent Gaussian noise of the given std added to each.

    The draws are float32 (a third faster than float64; noise needs no more digits), scaled and
    added in place: no temporaries the size of the batch.
    """
    levels = noise.as_dict()
    out = {}
    for name, values in signals.items():
        if levels.get(name, 0.0) > 0:
            noisy = rng.standard_normal(values.shape, dtype=np.float32).astype(np.float64)
            noisy *= levels[name]
            noisy += values
            out[name] = noisy
        else:
            out[name] = values.copy()
    return out
