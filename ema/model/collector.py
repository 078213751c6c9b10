"""The cyclic garbage collector, set for a program that loads NumPy, SciPy, Numba and the kernels.

Loading them allocates objects that live as long as the process. CPython collects its youngest generation every
700 allocations, and each collection of an older one walks what survived: while they load, the collector walks
them again and again (a fifth of the loading's time when torch's million objects were among them). Collected
every ``YOUNG_COLLECTION`` allocations instead (the older generations at their usual ratios), the loading is
spared that time, and a window's own garbage is still collected within a fraction of one window. The program
that starts sets it first thing (``ema`` itself, then every entry point's
``ema.model.runtime.configure_simulator``); importing sets nothing.
"""

from __future__ import annotations

import gc

YOUNG_COLLECTION = 10_000  # allocations between two collections of the youngest generation (CPython's default: 700)


def collect_less_often() -> None:
    """The youngest generation collected every ``YOUNG_COLLECTION`` allocations, the older ones as they were."""
    _, middle, oldest = gc.get_threshold()
    gc.set_threshold(YOUNG_COLLECTION, middle, oldest)
