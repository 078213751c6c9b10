"""Numba physics of the elevator EMA: parameters, aircraft, commands, kernels, batch API."""

import os


def _prefer_wide_vectors() -> None:
    """Let LLVM use 512-bit vectors where the CPU has them.

    LLVM tunes AVX-512 CPUs to prefer 256-bit vectors; the kernel's lane loop is instruction-bound,
    and 8 lanes per instruction instead of 4 measured ~1.5x faster on this project's machines.
    Numba reads its target features once, at import, so this must run before numba is imported;
    a user's own NUMBA_CPU_FEATURES wins.
    """
    if "NUMBA_CPU_FEATURES" in os.environ:
        return
    import llvmlite.binding as llvm

    features = llvm.get_host_cpu_features()
    if features.get("avx512f"):
        os.environ["NUMBA_CPU_FEATURES"] = features.flatten() + ",-prefer-256-bit"


_prefer_wide_vectors()
