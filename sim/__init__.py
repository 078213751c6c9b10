"""Numba physics of the elevator EMA: parameters, aircraft, commands, kernels, batch API.

Importing the package tunes Numba before Numba is imported (it reads its configuration once);
a user's own NUMBA_CPU_FEATURES or NUMBA_THREADING_LAYER wins.
"""

import os


def _prefer_wide_vectors() -> None:
    """Let LLVM use 512-bit vectors where the CPU has them.

    LLVM tunes AVX-512 CPUs to prefer 256-bit vectors; the kernel's lane loop is instruction-bound,
    and 8 lanes per instruction instead of 4 measured ~1.5x faster on this project's machines.
    """
    if "NUMBA_CPU_FEATURES" in os.environ:
        return
    import llvmlite.binding as llvm

    features = llvm.get_host_cpu_features()
    if features.get("avx512f"):
        os.environ["NUMBA_CPU_FEATURES"] = features.flatten() + ",-prefer-256-bit"


def _quiet_thread_pool() -> None:
    """Use Numba's own thread pool, not OpenMP.

    torch brings its own OpenMP runtime; with Numba on a second one, the idle workers of one spin
    while the other computes, and a training that takes 0.7 s took 21 s here. Numba's workqueue
    pool sleeps when idle. It must not be entered from two threads at once, and is not: the service
    runs one pipeline at a time in one worker thread.
    """
    os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")


_prefer_wide_vectors()
_quiet_thread_pool()
