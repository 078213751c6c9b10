"""Sensor noise drawn onto simulated signals: each sensor's AR(1) noise at the log rate, as the actuator
document's ``sensor_noise`` sets its std and correlation time (``ema.model.noise.SensorNoise``)."""

from __future__ import annotations

import functools
from collections.abc import Mapping
from types import MappingProxyType

import numpy as np
from numba import njit

from ema.model import runtime
from ema.model.noise import SensorNoise


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
