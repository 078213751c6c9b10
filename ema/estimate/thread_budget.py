"""The process's one thread budget, set by the program that starts (the CLI, the service, a worker).

The simulator runs its groups on ``threads`` threads of its own (``ema.model.runtime``), and NumPy's BLAS,
which also trains the network (a 16-input, 100-neuron layer on a hundred examples), gets one thread: its
small products gain nothing from a team, and on a shared computer a team whose member the OS has parked
stalls at every barrier. So the whole budget goes to the simulator.
"""

from __future__ import annotations

import os

from ema.model import runtime as sim_runtime
from ema.model.bounds import MAX_THREADS

ENVIRONMENT = "EMA_THREADS"


def budget(threads: int | None = None) -> int | None:
    """The budget asked for: the argument, else EMA_THREADS, else None (the usable cores)."""
    if threads is not None:
        return threads
    text = os.environ.get(ENVIRONMENT)
    if text:
        from ema.model.checks import InputError

        if not text.isdigit() or not 1 <= int(text) <= MAX_THREADS:
            raise InputError(ENVIRONMENT, f"must be an integer in [1, {MAX_THREADS}], got {text!r}")
        return int(text)
    return None


def configure(threads: int | None = None) -> int:
    """Set the budget for this process; returns the simulator's thread count."""
    return sim_runtime.configure_simulator(budget(threads))
