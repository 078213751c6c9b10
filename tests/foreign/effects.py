"""The calibration study's cases: effects drawn in the foreign implementation's own forms (test-only).

Sizes are those the calibration issue reported, each drawn per seed; ``scale`` multiplies the
departure from the base model (0.2x to 20x for the study).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tests.foreign.physics import Effects

Case = Callable[[np.random.Generator, float], Effects]


def _scaled(neutral: float, value: float, scale: float) -> float:
    return neutral + scale * (value - neutral)


def _gain(value: float, scale: float) -> float:
    """A gain's departure scaled, held within 0.5–1.5: 20x an 8 % departure is no actuator that runs."""
    return float(np.clip(_scaled(1.0, value, scale), 0.5, 1.5))


CASES: dict[str, Case] = {
    "clean": lambda rng, k: Effects(),
    "viscous": lambda rng, k: Effects(viscous_factor=_scaled(1.0, rng.uniform(1.5, 3.0), k)),
    "torque_constant": lambda rng, k: Effects(torque_constant_gain=_gain(rng.uniform(0.85, 0.93), k)),
    "current_sensor_gain": lambda rng, k: Effects(
        current_sensor_gain=_gain(rng.choice([rng.uniform(0.94, 0.97), rng.uniform(1.04, 1.10)]), k)
    ),
    "hinge_moment_bias": lambda rng, k: Effects(hinge_bias_nm=k * rng.choice([-1, 1]) * rng.uniform(20.0, 35.0)),
    # a Hall sensor off zero by a few tenths of an ampere, which the loop feeds back as it logs
    "current_sensor_offset": lambda rng, k: Effects(current_bias_a=k * rng.choice([-1, 1]) * rng.uniform(0.2, 0.5)),
    "position_friction": lambda rng, k: Effects(
        bump_nm=k * rng.uniform(0.03, 0.05),
        bump_centre_deg=rng.uniform(-8.0, 8.0),
        bump_width_deg=rng.uniform(1.5, 2.0),
    ),
    "backlash": lambda rng, k: Effects(backlash_factor=_scaled(1.0, rng.uniform(3.0, 6.0), k)),
    "cogging": lambda rng, k: Effects(
        cogging_nm=k * rng.uniform(0.015, 0.03), cogging_periods=12.0, cogging_phase_rad=rng.uniform(-np.pi, np.pi)
    ),
    "stribeck": lambda rng, k: Effects(
        stribeck_nm=k * rng.uniform(0.02, 0.04), stribeck_speed_radps=rng.uniform(80, 250)
    ),
    "drift": lambda rng, k: Effects(drift_per_s=k * rng.uniform(0.3, 0.6)),  # FDJ +15-30 % over a 0.5 s window
    "inertia": lambda rng, k: Effects(
        inertia_factor=_gain(rng.choice([rng.uniform(0.88, 0.94), rng.uniform(1.06, 1.12)]), k)
    ),
}
