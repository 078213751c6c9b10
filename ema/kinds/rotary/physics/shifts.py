"""A signal read later than logged, and Eq. 5.1's solution of the window so: what every reading of a
sensor's lag compares (``ema.kinds.rotary.prepare.alignment``, ``ema.kinds.rotary.prepare.hinge_lag``,
``ema.kinds.rotary.prepare.consistency``,
``ema.kinds.rotary.prepare.step_lag``)."""

from __future__ import annotations

import numpy as np

from ema.kinds.rotary.physics.features import as_read
from ema.kinds.rotary.physics.friction import FrictionSolution, SolveSettings, solve_friction
from ema.model.params import DriveConstants


def advanced(values: np.ndarray, samples: float) -> np.ndarray:
    """``values`` read ``samples`` later (linear interpolation; past the end, the last value)."""
    index = np.arange(len(values), dtype=np.float64)
    return np.interp(index + samples, index, values)


def shifted_solutions(
    signals: dict[str, np.ndarray],
    sample_rate_hz: float,
    lags: np.ndarray,
    drive: DriveConstants,
    name: str = "current_a",
    settings: SolveSettings = SolveSettings(),
) -> FrictionSolution:
    """The physics solution with signal ``name`` read ``lags`` samples later, one row per lag, one batched solution."""
    batch = dict(signals, **{name: np.stack([advanced(signals[name], lag) for lag in lags])})
    if name == "hinge_moment_nm":  # its reading leans on the deflection, row by row
        batch["position_deg"] = np.broadcast_to(signals["position_deg"], batch[name].shape)
    read = dict(as_read(batch, sample_rate_hz), position_deg=signals["position_deg"])
    return solve_friction(read, sample_rate_hz, drive, settings)
