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

import functools
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from types import MappingProxyType

import numpy as np
from numba import njit

from ema.model import runtime
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


@njit(cache=True)
def _correlate(white: np.ndarray, rho: float) -> None:
    """In place, white (rows, samples) of unit variance → stationary AR(1) of unit variance along each row:

    x[0] = w[0],   x[k] = ρ·x[k−1] + √(1 − ρ²)·w[k]
    """
    gain = np.sqrt(1.0 - rho * rho)
    for row in range(white.shape[0]):
        for k in range(1, white.shape[1]):
            white[row, k] = rho * white[row, k - 1] + gain * white[row, k]


def add_sensor_noise(
    signals: dict[str, np.ndarray], noise: SensorNoise, rng: np.random.Generator, sample_rate_hz: float | None = None
) -> dict[str, np.ndarray]:
    """A copy of ``signals`` with independent Gaussian noise of the given std (and correlation: then
    ``sample_rate_hz`` is required) added to each.

    The draws are float32 (a third faster than float64; noise needs no more digits), scaled and
    added in place: no temporaries the size of the batch.
    """
    return _scaled(signals, noise, _draw(rng, _drawn(signals, noise)), sample_rate_hz)


def add_seeded_noise(
    signals: dict[str, np.ndarray], noise: SensorNoise, seed: int, sample_rate_hz: float | None = None
) -> dict[str, np.ndarray]:
    """``add_sensor_noise`` with ``np.random.default_rng(seed)``, equal to it value for value.

    The unit draws depend only on the seed, the signals drawn and their shape, not on the noise's
    levels: a monitor answers window after window of one shape with one seed, so they are drawn once
    and kept (``_unit_draws``), and each window pays only for scaling them.
    """
    return _scaled(signals, noise, _unit_draws(seed, _drawn(signals, noise)), sample_rate_hz)


Drawn = tuple[tuple[str, tuple[int, ...]], ...]


def _drawn(signals: dict[str, np.ndarray], noise: SensorNoise) -> Drawn:
    """(name, shape) of each signal that gets noise (a level above 0), in the signals' order."""
    return tuple((name, values.shape) for name, values in signals.items() if getattr(noise, name, 0.0) > 0)


def _draw(rng: np.random.Generator, drawn: Drawn) -> dict[str, np.ndarray]:
    """Unit-variance float32 draws for each (signal, shape), in order: the one sequence both entries share."""
    return {name: rng.standard_normal(shape, dtype=np.float32) for name, shape in drawn}


@functools.lru_cache(maxsize=4)
def _unit_draws(seed: int, drawn: Drawn) -> Mapping[str, np.ndarray]:
    """``_draw`` of a fresh generator of ``seed``, kept read-only (the draws are shared between calls)."""
    draws = _draw(np.random.default_rng(seed), drawn)
    for draw in draws.values():
        draw.flags.writeable = False
    return MappingProxyType(draws)


def _scaled(
    signals: dict[str, np.ndarray], noise: SensorNoise, unit: Mapping[str, np.ndarray], sample_rate_hz: float | None
) -> dict[str, np.ndarray]:
    """Each signal plus its unit draws (correlated at its ρ where it has one) times its std; a copy of the rest."""
    levels = noise.as_dict()
    out = {}
    for name, values in signals.items():
        if name not in unit:
            out[name] = values.copy()
            continue
        if levels.get(f"{name}_corr_s", 0.0) > 0:
            if sample_rate_hz is None:
                raise ValueError(f"correlated {name} noise needs the sample rate")
            noisy = unit[name].astype(np.float64)
            _correlate(noisy.reshape(-1, values.shape[-1]), noise.correlation(name, sample_rate_hz))
            noisy *= levels[name]
            noisy += values
        else:
            noisy = _plus_scaled(values, unit[name], levels[name])
        out[name] = noisy
    return out


def _plus_scaled(values: np.ndarray, unit: np.ndarray, level: float) -> np.ndarray:
    """values + level·unit (``unit`` float32, of ``values``'s shape), its rows split over the simulator's threads."""
    rows = np.ascontiguousarray(values).reshape(-1, values.shape[-1])
    draws, out = unit.reshape(rows.shape), np.empty(rows.shape)
    runtime.run_rows(lambda a, b: _add_scaled(rows[a:b], draws[a:b], level, out[a:b]), len(rows))
    return out.reshape(values.shape)


@njit(cache=True, nogil=True)
def _add_scaled(values, unit, level, out):
    """out = values + level·unit, in one pass (rows (R, n); ``unit`` float32)."""
    for r in range(out.shape[0]):
        for k in range(out.shape[1]):
            out[r, k] = values[r, k] + level * np.float64(unit[r, k])
