"""Every test compiles its kernels as the product does.

Numba's cache does not key on LLVM's interleaving option (``ema.model.runtime``): a test that calls a kernel
directly, first in a fresh checkout, would leave the cache a kernel ~1.3x slower for every later process.
"""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _compiler_options() -> None:
    from ema.model import runtime

    runtime.compiler_options()
