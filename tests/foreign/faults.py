"""Logging faults of a window (test-only): a sensor that stops updating while the logger keeps writing its
last value, or a gap the logger fills with zeros, somewhere in the window.

Each fault rewrites a stretch of one signal of an ``ema-window/1`` document; where and how long is drawn
from the seed. A short fault falls where the shaft slews (it matters most there).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

SLEW_RADPS = 300.0  # where a short fault is placed: the motor this fast


@dataclass(frozen=True)
class Fault:
    signal: str
    fill: float | None  # None: the last value before the stretch held; else the value written over it
    share: tuple[float, float] = (0.05, 0.25)  # of the window, drawn uniformly ...
    duration_s: tuple[float, float] | None = None  # ... or this long instead, where the shaft slews


FAULTS: dict[str, Fault] = {
    "speed stops updating over 5-25 %": Fault("motor_speed_radps", None),
    "current gap filled with 0 over 5-25 %": Fault("current_a", 0.0),
    "hinge moment stops updating over 5-25 %": Fault("hinge_moment_nm", None),
    "position stops updating over 5-25 %": Fault("position_deg", None),
    "current at 0 for 0.5-2 ms at slew": Fault("current_a", 0.0, duration_s=(5e-4, 2e-3)),
    "speed stops updating for 0.5-2 ms at slew": Fault("motor_speed_radps", None, duration_s=(5e-4, 2e-3)),
}


def stretch(document: dict, fault: Fault, seed: int) -> tuple[int, int]:
    """[start, stop) of the samples ``fault`` rewrites in ``document``, drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    n, rate = len(document["signals"][fault.signal]), document["sample_rate_hz"]
    if fault.duration_s is None:
        length = int(rng.uniform(*fault.share) * n)
        start = int(rng.integers(1, n - length - 1))
        return start, start + length
    length = max(2, round(rng.uniform(*fault.duration_s) * rate))
    fast = np.flatnonzero(np.abs(np.asarray(document["signals"]["motor_speed_radps"][: n - length - 1])) > SLEW_RADPS)
    start = int(rng.choice(fast[fast > 0])) if np.any(fast > 0) else int(rng.integers(1, n - length - 1))
    return start, start + length


def frozen(document: dict, signal: str, start: int, stop: int, fill: float | None = None) -> dict:
    """``document`` with ``signal`` holding its sample at ``start`` (or ``fill``) until ``stop``."""
    out = copy.deepcopy(document)
    samples = out["signals"][signal]
    samples[start:stop] = [samples[start] if fill is None else fill] * (stop - start)
    return out


def with_fault(document: dict, fault: Fault, seed: int) -> dict:
    """``document`` as a logger with ``fault`` wrote it."""
    return frozen(document, fault.signal, *stretch(document, fault, seed), fault.fill)
