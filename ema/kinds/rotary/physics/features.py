"""One preprocessing for simulated and measured windows alike: the signals as read (the hinge moment
denoised, ``simulator.hinge``), residual torque, then resampling.

Measured and simulated data must go through the very same function (thesis §5.7); this module
is that function. Resampling to K timesteps takes the mean over K equal bins rather than
interpolating: with sensor noise, a bin mean keeps every sample's information and averages its
noise down, where point interpolation would throw most samples away.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ema.kinds.rotary.physics.friction import FrictionSolution, SolveSettings, solve_friction
from ema.kinds.rotary.simulator.hinge import denoised_hinge_nm
from ema.kinds.rotary.simulator.residual import residual_torque_nm
from ema.model.checks import InputError
from ema.model.params import DriveConstants

INPUT_SETS = {
    # the thesis's two input sets (§5.5): residual torque alone, and its "input map"
    "residual_torque": ("residual_torque",),
    "input_map": ("residual_torque", "motor_speed", "hinge_moment"),
}


def as_read(signals: Mapping[str, np.ndarray], sample_rate_hz: float) -> dict[str, np.ndarray]:
    """The signals as every estimator reads them: the hinge moment denoised along the deflection
    (``simulator.hinge``), the rest as logged. One window (n,) or a batch (N, n) per signal."""
    out = dict(signals)
    out["hinge_moment_nm"] = denoised_hinge_nm(signals["hinge_moment_nm"], signals["position_deg"], sample_rate_hz)
    return out


def solve_as_read(
    signals: Mapping[str, np.ndarray],
    sample_rate_hz: float,
    drive: DriveConstants,
    settings: SolveSettings = SolveSettings(),
) -> FrictionSolution:
    """Eq. 5.1 solved (``ema.kinds.rotary.physics.friction``) on a window's signals read as every estimator reads
    them."""
    return solve_friction(as_read(signals, sample_rate_hz), sample_rate_hz, drive, settings)


def bin_means(values: np.ndarray, n_bins: int) -> np.ndarray:
    """Mean over ``n_bins`` contiguous bins along the last axis, covering every sample.

    Bin edges are the rounded multiples of n / n_bins, so bins differ by at most one sample
    when n_bins does not divide the window.
    """
    n = values.shape[-1]
    if not 1 <= n_bins <= n:
        raise InputError("n_timesteps", f"must be in [1, {n}] for a window of {n} samples, got {n_bins}")
    edges = np.round(np.linspace(0, n, n_bins + 1)).astype(np.int64)
    return np.add.reduceat(values, edges[:-1], axis=-1) / np.diff(edges)


def sliding_features(residual_nm: np.ndarray, sliding: np.ndarray, n_timesteps: int) -> np.ndarray:
    """Network inputs (n_windows, n_timesteps): T_R averaged over the sliding samples of each bin (0 where none).

    ``sliding`` is the measured window's mask (Eq. 5.1's samples), applied to every simulation of
    its dataset alike. Outside it the shaft rests or hunts in the backlash, a limit cycle that no
    two implementations of the model reproduce sample for sample: a network that reads it learns
    the simulator's hunting, not the transmission's friction.
    """
    weight = sliding.astype(np.float64)
    counts = bin_means(weight[None], n_timesteps)
    sums = bin_means(np.atleast_2d(residual_nm) * weight, n_timesteps)
    return np.where(counts > 0, sums / np.maximum(counts, 1e-12), 0.0)


def features_from_residual(
    residual_nm: np.ndarray, signals: Mapping[str, np.ndarray], n_timesteps: int, input_set: str = "residual_torque"
) -> np.ndarray:
    """Network inputs (n_windows, n_channels · n_timesteps), channels side by side, from a reconstructed T_R
    (n_windows, n_samples) and the signals beside it."""
    if input_set not in INPUT_SETS:
        raise InputError("inputs", f"unknown input set {input_set!r}; known: {', '.join(INPUT_SETS)}")
    channels = {
        "residual_torque": residual_nm,
        "motor_speed": signals["motor_speed_radps"],
        "hinge_moment": signals["hinge_moment_nm"],
    }
    return np.concatenate(
        [bin_means(np.atleast_2d(channels[name]), n_timesteps) for name in INPUT_SETS[input_set]], axis=-1
    )


def features(
    signals: Mapping[str, np.ndarray],
    sample_rate_hz: float,
    n_timesteps: int,
    drive: DriveConstants,
    input_set: str = "residual_torque",
) -> np.ndarray:
    """Network inputs from window signals: (n_windows, n_channels · n_timesteps), channels side by side.

    ``signals`` holds (n_samples,) arrays for one window or (n_windows, n_samples) for a batch.
    """
    current = np.atleast_2d(signals["current_a"])
    speed = np.atleast_2d(signals["motor_speed_radps"])
    hinge = np.atleast_2d(signals["hinge_moment_nm"])
    residual = residual_torque_nm(current, speed, hinge, sample_rate_hz, drive)
    beside = {"motor_speed_radps": speed, "hinge_moment_nm": hinge}
    return features_from_residual(residual, beside, n_timesteps, input_set)
