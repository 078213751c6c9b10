"""Whether the answers past the issue's bound are more than honest stds expect, and whether one such
answer is the noise's tail or a bias the window carries.

An unbiased answer of std σ (as a share of the range) passes the bound with probability
erfc(bound / (σ·√2)); summed over a group's answers, that is how many errors past the bound its own
stds promise. A single answer far out (|z| > 3) is either the noise's tail or a bias of that window:
answered again with fresh realizations of the same window's sensor noise (``draw(noise_seed=...)``:
the same motion, noise levels and filters), a tail reads |z| ~ 1, a bias keeps its sign and size.
Rolling the window's own noise along it instead would not do: the periodogram stays the same, and
the slow part of the noise, where a window's answer is decided, with it.
"""

from __future__ import annotations

import math

import numpy as np

BOUND = 0.10  # issue 9: no window's error over 10 % of the range
FIRST_NOISE_SEED = 900_000  # the redraws' noise: apart from every seed the benchmarks draw windows with


def expected_over(stds: np.ndarray) -> float:
    """Answers expected past ``BOUND`` for unbiased Gaussian answers with these stds (shares of the range)."""
    return float(sum(math.erfc(BOUND / s / math.sqrt(2)) for s in stds if s > 0))
