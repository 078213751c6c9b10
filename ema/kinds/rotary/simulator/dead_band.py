"""The backlash as a path: where a motor-side travel leaves the elevator behind a dead band.

The elevator angle is held until the motor reaches a face of the band, then driven by it (the
simulator's ``kernels.advance`` does the same at every step):

    y[0] = x[0] + s·h,    y[k] = min(max(y[k−1], x[k] − h), x[k] + h)

for a half width h and a start s ∈ [−1, 1] (where in the band the window began). Its travel lags
the motor's by up to 2h at every reversal, whatever the motion, so a slope of the elevator's
angle on y is the drive's kinematic gain for any width of the band (``ema.kinds.rotary.prepare.consistency``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ema.model.checks import InputError, finite_array


@njit(cache=True)
def _paths(travel: np.ndarray, half_widths: np.ndarray, starts: np.ndarray, out: np.ndarray) -> None:
    for row in range(half_widths.shape[0]):
        h = half_widths[row]
        y = travel[0] + starts[row] * h
        for k in range(travel.shape[0]):
            y = min(max(y, travel[k] - h), travel[k] + h)
            out[row, k] = y


def dead_band_paths(travel_rad: np.ndarray, half_widths_rad: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """The paths y (module docstring) of ``travel_rad`` (n,) through bands of ``half_widths_rad`` (m,)
    ≥ 0, each begun at ``starts`` (m,) in [−1, 1] of its half width: (m, n), in the travel's unit."""
    travel = finite_array("travel_rad", travel_rad, ndim=1)
    half_widths = finite_array("half_widths_rad", half_widths_rad, ndim=1)
    begun = finite_array("starts", starts, ndim=1)
    if half_widths.shape != begun.shape or np.any(half_widths < 0) or np.any(np.abs(begun) > 1):
        raise InputError("half_widths_rad", "needs one start in [−1, 1] per half width ≥ 0")
    out = np.empty((len(half_widths), len(travel)))
    if len(travel):
        _paths(travel, half_widths, begun, out)
    return out
