"""A logged window made ready for the pipeline: a bounded number of samples, and what was done to it.

Logs come at 1–100 kHz and last 0.1–10 s. The simulator runs at 1 µs whatever the log rate, but
every later stage (reconstruction, features, the friction fit) costs per logged sample, and a
batch of simulations records every sample of every simulation. So the window is averaged over
f adjacent samples first: interval means of interval means are the interval means of the longer
intervals, exactly, which is also what the simulations record at the lower rate. ``f`` keeps the
rate at or below ``MAX_RATE_HZ`` (the 2 ms reconstruction needs no more) and the samples at or
below ``MAX_SAMPLES`` (a 10 s window is processed at 1 kHz): memory and time grow at most
linearly with the duration, and are bounded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from sim.batch import COMMAND_MARGIN_DEG
from sim.params import ActuatorParams
from sim.window import Window

MAX_RATE_HZ = 10_000.0
MAX_SAMPLES = 10_000


@dataclass(frozen=True)
class Prepared:
    window: Window  # what the pipeline processes
    factor: int  # adjacent samples averaged into one
    original_samples: int
    original_rate_hz: float
    command_clipped_fraction: float  # share of command samples past the end stops (the actuator saturates)


def averaging_factor(n_samples: int, rate_hz: float) -> int:
    """The smallest f with rate / f ≤ MAX_RATE_HZ and n / f ≤ MAX_SAMPLES."""
    return max(1, math.ceil(rate_hz / MAX_RATE_HZ - 1e-9), math.ceil(n_samples / MAX_SAMPLES - 1e-9))


def prepare(window: Window, actuator: ActuatorParams = ActuatorParams()) -> Prepared:
    """Average ``window`` down to the pipeline's sizes; say how far its command reached past the stops."""
    factor = averaging_factor(window.n_samples, window.sample_rate_hz)
    command = window.signals["command_deg"]
    clipped = float(np.mean(np.abs(command) > actuator.end_stop_deg + COMMAND_MARGIN_DEG))
    if factor > 1:
        n = window.n_samples // factor * factor
        signals = {name: values[:n].reshape(-1, factor).mean(axis=1) for name, values in window.signals.items()}
        window = replace(window, signals=signals, sample_rate_hz=window.sample_rate_hz / factor)
    return Prepared(window, factor, len(command), window.sample_rate_hz * factor, clipped)
