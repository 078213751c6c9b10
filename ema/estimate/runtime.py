"""The process's one thread budget, set by the program that starts (the CLI, the service, a worker).

The simulator runs its groups on ``threads`` threads of its own (``ema.model.runtime``). torch trains a
16-input, 100-neuron network on a hundred examples: its OpenMP team only adds waiting, and on a
shared computer a team whose member the OS has parked stalls at every barrier (training went
from 0.7 s to 19 s beside another CPU-bound job). So torch gets one intra-op and one inter-op
thread, and the budget goes to the simulator.

torch's optimizers mark a few of their methods "never compile" through a wrapper that imports torch's compiler
(``torch._dynamo``: a second of imports, paid by every process at its first optimizer) on its first call. ema never
compiles, so the set-up hands each wrapper the plain method as its already-disabled form: the same call, without
the import.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading

from ema.model import runtime as sim_runtime
from ema.model.bounds import MAX_THREADS

ENVIRONMENT = "EMA_THREADS"
_TORCH_LOCK = threading.Lock()
_torch_pending = False  # a budget was set whose torch part is not applied yet (torch not loaded then)


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
    """Set the budget for this process; returns the simulator's thread count. torch's part is set here where torch
    is loaded already, else when the learn stage loads it (``torch_ready``): a process that reads only windows no
    network learns from (a slow log, a ball screw's) never loads torch."""
    global _torch_pending
    count = sim_runtime.configure_simulator(budget(threads))
    _torch_pending = True
    if "torch" in sys.modules:
        torch_ready()
    return count


def torch_ready() -> None:
    """torch's part of a budget ``configure`` set, once: one intra-op and one inter-op thread, its optimizers
    without the compiler import (module docstring). Called by the learn stage before it trains; nothing where no
    budget was set (a library's caller keeps torch as it had it)."""
    global _torch_pending
    with _TORCH_LOCK:
        if not _torch_pending:
            return
        import torch

        _without_compiler_import()
        if torch.get_num_threads() != 1:
            torch.set_num_threads(1)
        with contextlib.suppress(RuntimeError):  # set once already: torch allows it only before any parallel work
            torch.set_num_interop_threads(1)
        _torch_pending = False


COMPILER_GUARDED = ("add_param_group", "zero_grad", "state_dict", "load_state_dict")  # torch.optim.Optimizer's


def _without_compiler_import() -> None:
    """Each guarded optimizer method's cached "disabled" form set to the method itself (module docstring)."""
    from torch.optim.optimizer import Optimizer

    for name in COMPILER_GUARDED:
        plain = getattr(getattr(Optimizer, name), "__wrapped__", None)
        if plain is not None and getattr(plain, "__dynamo_disable", None) is None:
            setattr(plain, "__dynamo_disable", plain)
