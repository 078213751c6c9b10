"""The generic curves' basis: piecewise-linear hats on uniform knots (``ema.kinds.rotary.families``)."""

from __future__ import annotations

import numpy as np


def hats(x: np.ndarray, knots: np.ndarray) -> np.ndarray:
    """Piecewise-linear basis (m, K − 1) on ``knots`` (uniform), the first dropped: a function that is 0
    at the first knot, so that it does not compete with the constant FDJ column."""
    step = knots[1] - knots[0]
    u = np.clip((x - knots[0]) / step, 0.0, len(knots) - 1.0)
    columns = np.maximum(0.0, 1.0 - np.abs(u[:, None] - np.arange(len(knots))[None, :]))
    return columns[:, 1:]


def uniform_knots(x: np.ndarray, count: int) -> np.ndarray:
    """``count`` uniform knots over the 1-99 % range of ``x``."""
    low, high = np.quantile(x, [0.01, 0.99])
    if high <= low:
        high = low + 1e-9
    return np.linspace(low, high, count)
