"""How noisy a measured window is, so that training sees what the estimator will see."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from sim.noise import SensorNoise

NOISY_SIGNALS = ("position_deg", "motor_speed_radps", "current_a", "hinge_moment_nm")


def white_noise_std(values: np.ndarray) -> float:
    """Robust std of white noise on a smooth signal: MAD of the second difference / √6.

    Δ²x of white noise has variance 6σ²; the smooth signal contributes little to it at 10 kHz, and
    the median ignores the few samples where the motion itself turns sharply.
    """
    second = np.diff(values, n=2)
    mad = np.median(np.abs(second - np.median(second)))
    return float(1.4826 * mad / np.sqrt(6.0))


def excess_noise(measured: Mapping[str, np.ndarray], clean: Mapping[str, np.ndarray]) -> SensorNoise:
    """Noise in ``measured`` beyond what the model's own ``clean`` signals show (e.g. PWM ripple).

    Both are one window's signals; variances subtract because sensor noise is independent of it.
    """
    levels = {}
    for name in NOISY_SIGNALS:
        excess = white_noise_std(measured[name]) ** 2 - white_noise_std(clean[name]) ** 2
        levels[name] = float(np.sqrt(max(excess, 0.0)))
    return SensorNoise(**levels)
