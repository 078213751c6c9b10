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
from numba import njit

from ema.kinds.rotary.simulator.residual import kernel_samples
from ema.model import runtime
from ema.model.checks import InputError

# A 3 Hz short-period swing loses 2.4 % of its amplitude to a 40 ms mean; 10 kHz noise, 20x.
HINGE_SMOOTHING_S = 0.04


def local_line(values: np.ndarray, width: int) -> np.ndarray:
    """At each sample, the least-squares line through the ``width`` samples nearest it, there (last axis).

    Inside the array that window is centred and the line's value is the plain mean (O(n) by a
    running sum); within width/2 of an end the window stops at the end and the line through
    it is evaluated off-centre. A straight line passes unchanged, and no output leans on fewer
    than ``width`` samples (a reflected pad would: at the edge sample it returns that sample).
    """
    values = np.asarray(values, dtype=np.float64)
    n = values.shape[-1]
    width = _line_width(width, n)
    if width < 3:
        return values.copy()
    rows = np.ascontiguousarray(values.reshape(-1, n))
    out = np.empty_like(rows)
    runtime.run_rows(lambda a, b: _local_line_rows(rows[a:b], width, out[a:b]), len(out))
    return out.reshape(values.shape)


def _line_width(width: int, n: int) -> int:
    """The samples a local line spans: ``width`` made odd (rounded down), at most ``n`` (odd)."""
    return min(width - (1 - width % 2), n - (1 - n % 2))


def denoised_hinge_nm(
    hinge_moment_nm: np.ndarray,
    position_deg: np.ndarray,
    sample_rate_hz: float,
    span_s: float = HINGE_SMOOTHING_S,
) -> np.ndarray:
    """H_read (module docstring) for one window (n,) or a batch (N, n), time along the last axis."""
    hinge = np.asarray(hinge_moment_nm, dtype=np.float64)
    position = np.asarray(position_deg, dtype=np.float64)
    if hinge.shape != position.shape:
        raise InputError("signals", f"shapes differ: hinge {hinge.shape}, position {position.shape}")
    n = hinge.shape[-1]
    width = _line_width(kernel_samples(sample_rate_hz, span_s), n)
    hinge_rows, position_rows = (np.ascontiguousarray(x.reshape(-1, n)) for x in (hinge, position))
    out = np.empty(hinge_rows.shape)
    runtime.run_rows(lambda a, b: _denoise_rows(hinge_rows[a:b], position_rows[a:b], width, out[a:b]), len(out))
    return out.reshape(hinge.shape)


@njit(cache=True, nogil=True)
def _local_line(values, width, out):
    """out (n,) = the local line of ``values`` (n,) over ``width`` (odd, 3 ≤ width ≤ n) samples."""
    n, half = values.shape[0], width // 2
    total = 0.0
    for k in range(width):
        total += values[k]
    for i in range(half, n - half):
        out[i] = total / width
        if i + half + 1 < n:
            total += values[i + half + 1] - values[i - half]
    denominator = 0.0
    for j in range(width):
        denominator += (j - half) ** 2
    for start, first_out, last_out in ((0, 0, half), (n - width, n - half, n)):
        mean, moment = 0.0, 0.0
        for j in range(width):
            mean += values[start + j]
            moment += values[start + j] * (j - half)
        mean /= width
        for i in range(first_out, last_out):
            out[i] = mean + moment / denominator * (i - start - half)


@njit(cache=True, nogil=True)
def _local_line_rows(rows, width, out):
    """out (R, n) = the local line of each row of ``rows`` (R, n) over ``width`` samples."""
    for r in range(rows.shape[0]):
        _local_line(rows[r], width, out[r])


@njit(cache=True, nogil=True)
def _denoise_rows(hinge, position, width, out):
    """out (R, n) = H_read of hinge and position (R, n) over ``width`` samples (1: the hinge as logged)."""
    n = hinge.shape[1]
    fast = np.empty(n)
    for r in range(hinge.shape[0]):
        if width < 3:
            out[r] = hinge[r]
            continue
        _local_line(hinge[r], width, out[r])
        _local_line(position[r], width, fast)
        spread, covariance = 0.0, 0.0
        for k in range(n):
            fast[k] = position[r, k] - fast[k]
            spread += fast[k] * fast[k]
            covariance += (hinge[r, k] - out[r, k]) * fast[k]
        slope = covariance / spread if spread > 0 else 0.0
        for k in range(n):
            out[r, k] += slope * fast[k]
