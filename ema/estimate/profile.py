"""η_O's span and its likelihood profile: where every search of η_O in ema looks, and how a χ² profile over it
gives η_O's std (the rotary's Eq. 5.1, the quasi-static readings of the rotary and the ball screw)."""

from __future__ import annotations

import numpy as np

ETA_O_SEARCH = (0.20, 0.999)  # η_O searched over, by every search and profile of it in ema; Case 1C reaches 0.44


PROFILE_STEP = 0.005  # a likelihood profile over η_O (its width gives the std) is drawn at this step


def profile_grid() -> np.ndarray:
    """η_O every ``PROFILE_STEP`` over ``ETA_O_SEARCH``: where a likelihood profile is drawn whole (the
    quasi-static reading's, the drive solution's), its width being the std."""
    low, high = ETA_O_SEARCH
    return low + PROFILE_STEP * np.arange(int((high - low) / PROFILE_STEP + 1e-9) + 1)


def profile_std(grid: np.ndarray, chi2: np.ndarray, rise: float = 1.0) -> float:
    """η_O's std from its χ² profile over ``grid``: half the width where χ² lies within ``rise`` of its minimum
    (1: one std; a Birge ratio's square where the scatter exceeds the stated noise), never under one grid step
    (a profile no wider than its step is resolved only to it)."""
    inside = grid[chi2 <= np.min(chi2) + rise]
    return float(max((inside.max() - inside.min()) / 2.0, grid[1] - grid[0]))


ETA_GRID = profile_grid()  # η_O every PROFILE_STEP over the search's range: where a whole profile is drawn
