"""Sensor noise: what turns a clean simulation into what a real actuator's sensors would log.

Each sensor's noise is first-order autoregressive (AR(1)) at the log rate: per-sample std σ and a
correlation time τ, so that consecutive samples correlate by ρ = exp(−1 / (τ · rate)); τ = 0 is
white noise. A real sensor's noise is rarely white: an anti-aliasing filter, an averaging ADC or a
resolver's tracking loop correlates it over a few samples, a strain-gauge amplifier over many.
The estimates feel the noise's low frequencies, where AR(1) noise of the same σ carries
(1 + ρ) / (1 − ρ) times the power of white noise. Simulations that draw such noise white train
the network and set the stds on data quieter or louder than the window, where it counts.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ema.model.checks import in_range
from ema.model.params import MAX_CORRELATION_S

NOISY_SIGNALS = ("position_deg", "motor_speed_radps", "current_a", "hinge_moment_nm")


@dataclass(frozen=True)
class SensorNoise:
    """Standard deviation of each logged signal's noise, per sample at the log rate, and its correlation
    time ``<signal>_corr_s`` [s] (0: white)."""

    position_deg: float = 0.01  # resolver / LVDT [deg]
    motor_speed_radps: float = 0.5  # Hall-sensor speed [rad/s]
    current_a: float = 0.05  # phase-current sensor [A]
    hinge_moment_nm: float = 2.0  # strain gauge or computed load [N·m]
    command_deg: float = 0.0  # the command is a digital signal: exact
    position_deg_corr_s: float = 0.0
    motor_speed_radps_corr_s: float = 0.0
    current_a_corr_s: float = 0.0
    hinge_moment_nm_corr_s: float = 0.0

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            in_range(f"noise.{name}", value, 0.0, MAX_CORRELATION_S if name.endswith("_corr_s") else 1e3)

    def as_dict(self) -> dict[str, float]:
        return asdict(self)

    def correlation(self, name: str, sample_rate_hz: float) -> float:
        """ρ: the correlation of consecutive samples of ``name``'s noise at ``sample_rate_hz``."""
        tau_s = getattr(self, f"{name}_corr_s", 0.0)
        return float(np.exp(-1.0 / (tau_s * sample_rate_hz))) if tau_s > 0 else 0.0

    def mean_inflation(self, name: str, n_samples: int, sample_rate_hz: float) -> float:
        """How many times more the mean of ``n_samples`` consecutive samples of ``name``'s noise scatters than white
        noise's of the same per-sample std: √(n · Var(mean of unit AR(1)))."""
        return float(np.sqrt(n_samples * ar1_mean_variance(self.correlation(name, sample_rate_hz), n_samples)))

    def mean_std(self, name: str, n_samples: int, sample_rate_hz: float) -> float:
        """The std of the mean of ``n_samples`` consecutive samples of ``name``'s noise."""
        variance = ar1_mean_variance(self.correlation(name, sample_rate_hz), n_samples)
        return getattr(self, name) * float(np.sqrt(variance))


NO_NOISE = SensorNoise(0.0, 0.0, 0.0, 0.0, 0.0)


def ar1_mean_variance(rho: float, n: int) -> float:
    """Var(mean of n consecutive samples) of unit-variance AR(1) noise: (1/n²) Σᵢⱼ ρ^|i−j| (1/n when white)."""
    if rho == 0.0:
        return 1.0 / n
    k = np.arange(1, n)
    return float((n + 2.0 * np.sum((n - k) * rho**k)) / n**2)
