"""The simulator's kernel timed alone: what the latency benchmark states every latency against, beside its
yardstick, so that a day's drift in the machine's speed cancels in a ratio."""

from __future__ import annotations

import time

import numpy as np

from ema.kinds.rotary.simulator.batch import default_lanes, simulate_batch
from ema.kinds.rotary.simulator.commands import random_command_knots
from ema.model.actuator import THESIS
from ema.model.params import DEFAULT_RANGES, HealthParams


def kernel_seconds(simulations: int, samples: int, rate_hz: float, *, repeats: int = 2) -> tuple[float, int]:
    """(the best of ``repeats`` wall times [s] of ``simulations`` thesis windows of ``samples`` samples at
    ``rate_hz``, the lanes a group runs): health drawn over the default ranges and one random command, seed 0,
    the kernel compiled or loaded before the first timing."""
    rng = np.random.default_rng(0)
    health = HealthParams.uniform(simulations, DEFAULT_RANGES, rng)
    knots = random_command_knots(samples, rate_hz, rng)[0]
    simulate_batch(knots[:11], health, drive=THESIS.params)
    best = np.inf
    for _ in range(repeats):
        started = time.perf_counter()
        simulate_batch(knots, health, drive=THESIS.params)
        best = min(best, time.perf_counter() - started)
    return float(best), default_lanes(simulations)


def kernel_cached() -> bool | None:
    """Whether Numba's cache holds the simulator's kernel yet (None: a Numba whose private cache layout this
    cannot read): a fresh install compiles it on its first window, about 30 s."""
    from pathlib import Path

    from ema.kinds.rotary.simulator import kernels

    try:  # Numba's cache file of the dispatcher: private, so a layout it does not have says nothing
        index = Path(kernels.run_group._cache._cache_file._index_path)  # type: ignore[attr-defined]
    except AttributeError:
        return None
    return index.exists()
