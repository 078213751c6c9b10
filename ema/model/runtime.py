"""Process-wide choices for the simulator, made by the program that starts, never at import.

- **Threads.** Groups of simulations run on a pool of ``threads()`` threads (the kernel releases the
  GIL), and so do the row loops that read the simulated windows (``run_rows``). Numba's own
  threading layer is not used: a static split of the batch waits for its slowest thread, which on a
  shared computer is the one the OS has parked. A pool of our own takes groups from one queue: a parked
  thread delays only its group. The budget is shared with NumPy's BLAS (which also trains the network,
  ``ema.estimate.thread_budget``), which gets one thread: its small products and solves gain nothing from a
  team, and OpenBLAS's idle worker spins after each call, on a core a simulation group needs.
- **Vector width.** LLVM tunes AVX-512 CPUs to prefer 256-bit vectors; the lane loop is
  instruction-bound and measured ~1.5x faster with 512-bit ones (docs/benchmarks.md). Numba reads
  this when it first compiles or loads a kernel, so :func:`configure_simulator` must run before that; a
  user's own NUMBA_CPU_FEATURES wins.
- **Interleaving.** One step of a lane is a chain of dependent operations (controller, current,
  friction, speed, position: ~100 cycles). With one vector of lanes per iteration of the lane loop
  the CPU's scheduler holds little more than one such chain; with ``INTERLEAVE`` independent
  vectors per iteration it works on three at once (48 lanes: 3.2-3.6 -> 2.8 ns per lane-step, the
  same arithmetic, docs/benchmarks.md). Groups are then whole multiples of ``INTERLEAVE`` vectors
  (``ema.kinds.rotary.simulator.batch.LANE_MULTIPLE``), or their remainder runs scalar. The option is LLVM's, for every
  loop compiled afterwards (interleaving never changes a loop's result, and a loop of fewer
  iterations keeps its scalar path). Numba's cache does not key on it: a kernel compiled without it
  (by a test, a notebook) would be the cache's, ~1.3x slower, for every later process until its source
  changed. So the dispatchers (``run_rows``, ``map_on_pool``) set it, and the vector width, before any
  kernel they run, whoever calls them (``compiler_options``).
"""

from __future__ import annotations

import itertools
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from typing import TypeVar

from ema.model.bounds import MAX_THREADS
from ema.model.checks import InputError
from ema.model.collector import collect_less_often

INTERLEAVE = 3  # independent vectors per iteration of a vectorized loop (module docstring)
T = TypeVar("T")
R = TypeVar("R")


def available_cores() -> int:
    """Cores this process may run on (its affinity mask, not the machine's count)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


class _Budget:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.threads = available_cores()
        self.pool: ThreadPoolExecutor | None = None
        self.blas_limited = False  # the limit lasts for the process: set once (a fleet worker configures per window)
        self.interleaved = False  # LLVM's option, likewise
        self.compiler_set = False  # compiler_options has run


_BUDGET = _Budget()


def threads() -> int:
    """Threads the simulator may use."""
    return _BUDGET.threads


def set_threads(count: int) -> None:
    """Resize the simulator's thread pool (the next batch uses the new size)."""
    if not 1 <= count <= MAX_THREADS:
        raise InputError("threads", f"must be in [1, {MAX_THREADS}], got {count}")
    with _BUDGET.lock:
        if count != _BUDGET.threads and _BUDGET.pool is not None:
            _BUDGET.pool.shutdown(wait=True)
            _BUDGET.pool = None
        _BUDGET.threads = count


def shutdown() -> None:
    """Cancel the pool's queued groups and let its threads end after the group each runs (a few ms): the
    program's every exit path calls it. Python's exit would otherwise run every queued group first (an
    interrupted 4000-simulation batch kept its process alive for minutes)."""
    with _BUDGET.lock:
        if _BUDGET.pool is not None:
            _BUDGET.pool.shutdown(wait=False, cancel_futures=True)
            _BUDGET.pool = None


_THREAD = threading.local()  # ``on_pool``: set in the pool's own threads


def _mark_pool_thread() -> None:
    _THREAD.on_pool = True


def pool() -> ThreadPoolExecutor:
    """The shared pool, created on first use."""
    with _BUDGET.lock:
        if _BUDGET.pool is None:
            _BUDGET.pool = ThreadPoolExecutor(
                _BUDGET.threads, thread_name_prefix="ema-sim", initializer=_mark_pool_thread
            )
        return _BUDGET.pool


def _inline() -> bool:
    """Whether work must run in the calling thread: one thread, or a pool thread itself (waiting there for
    the pool's other threads could wait for ever: each of them may be waiting too)."""
    return threads() == 1 or getattr(_THREAD, "on_pool", False)


# Rows of a signal batch per thread below which a split costs more than it saves (a 5000-sample row: ~30 µs).
MIN_ROWS_PER_THREAD = 8


def run_rows(work: Callable[[int, int], None], n_rows: int) -> None:
    """``work(start, stop)`` over the rows [0, n_rows) of a signal batch, in one contiguous part per thread
    of the budget (none below ``MIN_ROWS_PER_THREAD`` rows), on the pool, inline when one part: for
    compiled loops over independent rows that release the GIL. Waits for every part (``wait_all``); inline
    in a pool thread."""
    compiler_options()
    parts = max(1, min(threads(), n_rows // MIN_ROWS_PER_THREAD))
    if parts == 1 or _inline():
        work(0, n_rows)
        return
    edges = [round(n_rows * k / parts) for k in range(parts + 1)]
    wait_all([pool().submit(work, a, b) for a, b in itertools.pairwise(edges)])


def map_on_pool(work: Callable[[T], R], items: Sequence[T]) -> list[R]:
    """``work`` of each item, in order, the items spread over the pool (inline with one thread or one item):
    for independent pieces of work whose compiled loops release the GIL; inline in a pool thread."""
    compiler_options()
    if _inline() or len(items) <= 1:
        return [work(item) for item in items]
    futures = [pool().submit(work, item) for item in items]
    wait_all(futures)
    return [future.result() for future in futures]


def wait_all(futures: Sequence[Future]) -> None:
    """Wait for every future of a batch; an error or an interrupt cancels those not started (the rest of
    the batch is not wanted) and is raised."""
    try:
        for future in futures:
            future.result()
    except BaseException:
        for future in futures:
            future.cancel()
        raise


def compiler_options() -> None:
    """The vector width and the interleaving every kernel is compiled (or loaded from the cache) under, set once
    per process before the first kernel runs (see the module docstring)."""
    if _BUDGET.compiler_set:
        return
    prefer_wide_vectors()
    interleave_vector_loops()
    _BUDGET.compiler_set = True


def prefer_wide_vectors() -> None:
    """Let LLVM use 512-bit vectors where the CPU has them (see the module docstring)."""
    if "NUMBA_CPU_FEATURES" in os.environ:
        return
    import llvmlite.binding as llvm
    from numba.core import config

    features = llvm.get_host_cpu_features()
    if features.get("avx512f"):
        config.CPU_FEATURES = features.flatten() + ",-prefer-256-bit"  # type: ignore[attr-defined]


def configure_simulator(threads: int | None = None) -> int:
    """The entry points' one call: vector width and interleaving, BLAS on one thread, the cyclic collector
    (``collect_less_often``), then the thread budget (default: the usable cores)."""
    compiler_options()
    collect_less_often()
    single_threaded_blas()
    set_threads(threads or available_cores())
    return _BUDGET.threads


def single_threaded_blas() -> None:
    """Limit every BLAS NumPy has loaded to one thread, for the rest of the process (threadpoolctl finds
    OpenBLAS, MKL or BLIS whatever their symbol names; a per-build ``ctypes`` call would not). Once per
    process: the search through the loaded libraries costs about a millisecond."""
    with _BUDGET.lock:
        if _BUDGET.blas_limited:
            return
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=1, user_api="blas")
        _BUDGET.blas_limited = True


def interleave_vector_loops() -> None:
    """Have LLVM put ``INTERLEAVE`` independent vectors in each iteration of the loops it vectorizes from now
    on (see the module docstring). Once per process."""
    with _BUDGET.lock:
        if _BUDGET.interleaved:
            return
        import llvmlite.binding as llvm

        llvm.set_option("ema", f"-force-vector-interleave={INTERLEAVE}")
        _BUDGET.interleaved = True
