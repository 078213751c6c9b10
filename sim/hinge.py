"""The hinge moment as the estimators read it: its sensor noise averaged down, its fast part kept.

A logged hinge moment is H_e = H_slow(t) + b·δ(t) + noise: the aircraft's part (trim, angle of
attack: short-period motion, periods of a few tenths of a second) and the deflection's own part
(b = q̄·S·c·C_hδ), which follows the elevator as fast as it moves. The strain gauge's noise
(~2 N·m a sample, ~4 mN·m at the motor shaft, as much as the current sensor's) enters the residual
torque and both load columns of Eq. 5.1; on a 0.1 s window it makes as much of the error as the
current sensor's noise does.

So the moment is split along the measured deflection, whose sensor is ~15x quieter in N·m:
b is the least-squares slope of the fast part of H_e on the fast part of δ (each minus its
``HINGE_SMOOTHING_S`` mean; measured, so nothing assumes the aircraft matches its model), and

    H_read = mean(H_e) + b·(δ − mean(δ))        (means over the ``HINGE_SMOOTHING_S`` around each
                                                  sample; near an end, a line through the nearest)

i.e. the slow part averaged over the window, the fast part as the deflection draws it. Where δ
does not move fast, b·(δ − mean δ) vanishes and H_read is the plain mean. The position sensor's
own noise passes through b (~12 N·m/deg · 0.01° ≈ 0.12 N·m a sample at 153 m/s, sea level),
so the hinge noise drops ~10x per sample at 10 kHz. The estimates respond mostly to the noise's
low frequencies, which no filter removes, so their error falls far less than the noise per sample.
Measured and simulated windows go through this one function, and simulations draw position noise
for it.
"""

from __future__ import annotations

import numpy as np

from sim.checks import InputError
from sim.residual import kernel_samples

# A 3 Hz short-period swing loses 2.4 % of its amplitude to a 40 ms mean; 10 kHz noise, 20x.
HINGE_SMOOTHING_S = 0.04


def local_line(values: np.ndarray, width: int) -> np.ndarray:
    """At each sample, the least-squares line through the ``width`` samples nearest it, there (last axis).

    Inside the array that window is centred and the line's value is the plain mean (O(n) by
    cumulative sums); within width/2 of an end the window stops at the end and the line through
    it is evaluated off-centre. A straight line passes unchanged, and no output leans on fewer
    than ``width`` samples (a reflected pad would: at the edge sample it returns that sample).
    """
    n = values.shape[-1]
    width = min(width, n - (1 - n % 2))  # odd, at most n
    half = width // 2
    if half < 1:
        return values.astype(np.float64, copy=True)
    sums = np.cumsum(values, axis=-1, dtype=np.float64)
    sums = np.concatenate([np.zeros_like(sums[..., :1]), sums], axis=-1)
    out = np.empty(values.shape)
    out[..., half : n - half] = (sums[..., width:] - sums[..., : n - width + 1]) / width
    offsets = np.arange(width) - half
    for ends, at in ((slice(0, width), slice(0, half)), (slice(n - width, n), slice(width - half, width))):
        block = values[..., ends]
        mean = block.mean(axis=-1, keepdims=True)
        slope = block @ offsets / np.sum(offsets**2)
        out[..., at.start + ends.start : at.stop + ends.start] = mean + slope[..., None] * offsets[at]
    return out


def denoised_hinge_nm(
    hinge_moment_nm: np.ndarray,
    position_deg: np.ndarray,
    sample_rate_hz: float,
    window_s: float = HINGE_SMOOTHING_S,
) -> np.ndarray:
    """H_read (module docstring) for one window (n,) or a batch (N, n), time along the last axis."""
    hinge = np.asarray(hinge_moment_nm, dtype=np.float64)
    position = np.asarray(position_deg, dtype=np.float64)
    if hinge.shape != position.shape:
        raise InputError("signals", f"shapes differ: hinge {hinge.shape}, position {position.shape}")
    width = kernel_samples(sample_rate_hz, window_s)
    slow_hinge = local_line(hinge, width)
    fast_position = position - local_line(position, width)
    spread = np.sum(fast_position**2, axis=-1, keepdims=True)
    covariance = np.sum((hinge - slow_hinge) * fast_position, axis=-1, keepdims=True)
    slope = np.divide(covariance, spread, out=np.zeros_like(spread), where=spread > 0)
    return slow_hinge + slope * fast_position
