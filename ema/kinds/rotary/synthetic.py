"""Synthetic windows: the model standing in for an actuator's log (for demos, tests and calibration)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ema.kinds.rotary.simulator.batch import InitialState, simulate_batch
from ema.kinds.rotary.simulator.commands import family_knots
from ema.kinds.rotary.simulator.effects import EffectSet
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.kinds.rotary.simulator.sensor_noise import add_sensor_noise
from ema.model.actuator import THESIS, RotaryActuator
from ema.model.aircraft import FlightCondition
from ema.model.bounds import (
    DEFAULT_SAMPLE_RATE_HZ,
    DURATION_RANGE_S,
    MAX_SAMPLES,
    MIN_SAMPLES,
    SAMPLE_RATE_RANGE_HZ,
)
from ema.model.checks import InputError, in_range
from ema.model.noise import SensorNoise
from ema.model.params import HealthParams
from ema.model.window import RotaryWindow


def synthetic_window(
    health: HealthParams,
    condition: FlightCondition | GroundLoad = FlightCondition(),
    *,
    seed: int = 0,
    duration_s: float = 0.5,
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ,
    noise: SensorNoise = SensorNoise(),
    effects: EffectSet = EffectSet(),
    actuator_id: str = "synthetic/elevator",
    window_id: str | None = None,
    command: str = "thesis",
    actuator: RotaryActuator = THESIS,
) -> RotaryWindow:
    """One window logged from the model of ``actuator``: a command of ``command``'s family
    (``simulator.commands.COMMAND_FAMILIES``), the actuator at rest where the command starts, sensor noise; in flight at
    ``condition``, or on the ground under a load cell's ``GroundLoad`` (the window then names no flight
    condition).

    ``seed`` fixes the command and the noise; ``health`` must hold one simulation. Without a ``window_id``
    the window is named by its content (``synthetic-`` and its digest), so two different windows never
    share a name.
    """
    n_samples = window_samples(duration_s, sample_rate_hz)
    rng = np.random.default_rng(seed)
    knots = family_knots(command, n_samples, sample_rate_hz, rng)
    stop = actuator.params.end_stop_deg - 1.0
    start = InitialState(position_deg=float(np.clip(knots[0], -stop, stop)))
    result = simulate_batch(
        knots, health, condition, start, sample_rate_hz, effects, drive=actuator.params, hinge=actuator.hinge
    )
    signals = add_sensor_noise(result.simulation(0), noise, rng)
    flight = condition if isinstance(condition, FlightCondition) else None
    window = RotaryWindow(signals, sample_rate_hz, flight, actuator_id, window_id or "synthetic")
    return window if window_id else replace(window, window_id=f"synthetic-{window.content_sha256()[:16]}")


def window_samples(duration_s: float, sample_rate_hz: float) -> int:
    """The samples a window of ``duration_s`` at ``sample_rate_hz`` holds; an InputError naming the field where
    either is out of its range or the count is one no window may hold (``ema-window/1``'s bounds): a command
    drawn over no time has no shape, and one ema would refuse to read is no window to write."""
    rate = in_range("sample_rate_hz", sample_rate_hz, *SAMPLE_RATE_RANGE_HZ, "Hz")
    duration = in_range("duration_s", duration_s, *DURATION_RANGE_S, "s")
    n_samples = round(duration * rate)
    if not MIN_SAMPLES <= n_samples <= MAX_SAMPLES:
        raise InputError(
            "duration_s",
            f"{duration:g} s at {rate:g} Hz is {n_samples} samples; a window holds {MIN_SAMPLES} to {MAX_SAMPLES}",
        )
    return n_samples
