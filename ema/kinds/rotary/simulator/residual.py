"""Residual-torque reconstruction (thesis Eq. 5.3, spec sign of H_e), for simulated and measured data alike.

T_R = k_T·I − J_M·dω_m/dt + H_e / n: the torque the transmission loses (dry + viscous friction),
from measured signals and known constants only. dω/dt is the slope of a least-squares line over a
centred window (a first-order Savitzky–Golay differentiator): at 10 kHz a plain difference turns
the 0.5 rad/s speed noise into ≈ 90 mN·m of J·dω/dt, more than FDJ; a 2 ms line cuts it to ≈ 5 mN·m
while leaving the 10–100 ms friction dynamics intact.

That slope is a weighted mean of the sample-to-sample accelerations (weights K_j, a parabola).
The torque terms are averaged with the same weights (between neighbouring samples, as the
accelerations are), so the result is the true T_R seen through one smoothing kernel: no spikes
where a fast transient meets a filter on one term only.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

from ema.model import runtime
from ema.model.checks import InputError, finite_array, in_range
from ema.model.params import DriveConstants

DERIVATIVE_SPAN_S = 2e-3
# Within this of the end stops the shaft may rest against them: T_R there is not friction.
END_STOP_MARGIN_DEG = 1.0


def derivative_weights(half_width: int, sample_rate_hz: float) -> np.ndarray:
    """Convolution weights of the least-squares slope over 2·half_width + 1 samples [1/s]."""
    offsets = np.arange(-half_width, half_width + 1, dtype=np.float64)
    return offsets / np.sum(offsets**2) * sample_rate_hz


def acceleration_weights(half_width: int) -> np.ndarray:
    """K_j, j = −h … h−1: the least-squares slope as a weighted mean of forward differences (sums to 1)."""
    offsets = np.arange(-half_width, half_width + 1, dtype=np.float64)
    slope = offsets / np.sum(offsets**2)
    return np.cumsum(slope[::-1])[::-1][1:]


def smoothing_weights(half_width: int) -> np.ndarray:
    """2h + 1 weights that average a signal as the slope averages the acceleration (sums to 1): a copy of
    the width's one computation (a window's reads smooth many times at one width)."""
    return _smoothing_weights(half_width).copy()


@functools.cache
def _smoothing_weights(half_width: int) -> np.ndarray:
    return np.convolve(acceleration_weights(half_width), [0.5, 0.5])


def kernel_samples(sample_rate_hz: float, span_s: float = DERIVATIVE_SPAN_S) -> int:
    """Samples the reconstruction kernel spans at this rate (2·half + 1)."""
    return 2 * max(1, round(span_s * sample_rate_hz / 2)) + 1


def _half_width(values: np.ndarray, sample_rate_hz: float, span_s: float) -> int:
    half = max(1, round(span_s * sample_rate_hz / 2))
    if values.shape[-1] <= 2 * half:
        raise InputError("signals", f"need more than {2 * half} samples to differentiate over {span_s:g} s")
    return half


def _correlate(values: np.ndarray, weights: np.ndarray, odd_extension: bool) -> np.ndarray:
    """Centred correlation along the last axis, the ends padded by reflection (point reflection if odd)."""
    values = np.asarray(values, dtype=np.float64)
    rows = np.ascontiguousarray(values.reshape(-1, values.shape[-1]))
    out = np.empty(rows.shape)
    weights = np.ascontiguousarray(weights, dtype=np.float64)
    runtime.run_rows(lambda a, b: _correlate_rows(rows[a:b], weights, odd_extension, out[a:b]), len(rows))
    return out.reshape(values.shape)


@njit(cache=True, nogil=True, inline="always")
def _pad(row, half, odd_extension, padded):
    """padded (n + 2·half,) = ``row`` reflected about its end samples (x[−k] = x[k]; with ``odd_extension``,
    2·x[0] − x[k])."""
    n = row.shape[0]
    padded[half : half + n] = row
    for k in range(1, half + 1):
        head, tail = row[k], row[n - 1 - k]
        if odd_extension:
            head, tail = 2 * row[0] - head, 2 * row[n - 1] - tail
        padded[half - k] = head
        padded[half + n - 1 + k] = tail


@njit(cache=True, nogil=True, inline="always")
def _correlate_padded(padded, weights, out):
    """out[i] = Σ_j weights[j] · padded[i + j], tap-outer: the inner loop runs along the row and vectorizes."""
    out[:] = 0.0
    for j in range(weights.shape[0]):
        w = weights[j]
        for i in range(out.shape[0]):
            out[i] += w * padded[i + j]


@njit(cache=True, nogil=True)
def _correlate_rows(rows, weights, odd_extension, out):
    """out[r, i] = Σ_j weights[j] · x[r, i + j − h], h = len(weights) // 2, rows (R, n), out (R, n), x the
    row reflected about its end samples (``_pad``)."""
    half = weights.shape[0] // 2
    padded = np.empty(rows.shape[1] + 2 * half)
    for r in range(rows.shape[0]):
        _pad(rows[r], half, odd_extension, padded)
        _correlate_padded(padded, weights, out[r])


@njit(cache=True, nogil=True)
def _residual_rows(signals, weights, constants, out):
    """out[r] = smoothing ⋆ (clip(k_T·I, ±T_M,max) + H_e / n) − J_M · (derivative ⋆ ω), rows (R, n), ⋆ the
    padded correlation of ``_correlate_rows`` (even for the torques, odd for the speed); ``signals`` =
    (I, ω, H_e), each (R, n), ``weights`` = (smoothing, derivative), ``constants`` = (k_T, T_M,max, n, J_M).
    The same operations in the same order as the separate steps, in one pass per row and without the
    batch-sized temporaries."""
    current, speed, hinge = signals
    smoothing, derivative = weights
    torque_constant, max_torque, gear, inertia = constants
    n, half = current.shape[1], smoothing.shape[0] // 2
    driving, padded = np.empty(n), np.empty(n + 2 * half)
    smooth, slope = np.empty(n), np.empty(n)
    for r in range(current.shape[0]):
        for i in range(n):
            driving[i] = min(max(torque_constant * current[r, i], -max_torque), max_torque) + hinge[r, i] / gear
        _pad(driving, half, False, padded)
        _correlate_padded(padded, smoothing, smooth)
        _pad(speed[r], half, True, padded)
        _correlate_padded(padded, derivative, slope)
        for i in range(n):
            out[r, i] = smooth[i] - inertia * slope[i]


def smoothed(values: np.ndarray, sample_rate_hz: float, span_s: float = DERIVATIVE_SPAN_S) -> np.ndarray:
    """``values`` averaged with the kernel that matches :func:`smooth_derivative`."""
    return _correlate(values, smoothing_weights(_half_width(values, sample_rate_hz, span_s)), odd_extension=False)


def smooth_derivative(values: np.ndarray, sample_rate_hz: float, span_s: float = DERIVATIVE_SPAN_S) -> np.ndarray:
    """d(values)/dt along the last axis by a centred least-squares line of ``span_s``.

    The ends are padded by point reflection (2·x₀ − x), which keeps the end slope, so the
    output has the input's length and no transient at the edges.
    """
    half = _half_width(values, sample_rate_hz, span_s)
    return _correlate(values, derivative_weights(half, sample_rate_hz), odd_extension=True)


def above_throughout(values: np.ndarray, threshold: float, width: int) -> np.ndarray:
    """Whether every sample of a centred window of ``width`` samples exceeds ``threshold`` (last axis),
    by a running count: O(n). False where the window runs past either end: the reconstruction's
    kernel is padded there, leaning on the last few samples (noise ~4x, the samples erring together)."""
    values = np.asarray(values, dtype=np.float64)
    n = values.shape[-1]
    rows = np.ascontiguousarray(values.reshape(-1, n))
    out = np.empty(rows.shape, dtype=np.bool_)
    _above_rows(rows, float(threshold), width // 2, out)
    return out.reshape(values.shape)


@njit(cache=True, nogil=True)
def _above_rows(rows, threshold, half, out):
    """out[r, i] = all(rows[r, i − half : i + half + 1] > threshold), False within ``half`` of an end."""
    n = rows.shape[1]
    for r in range(rows.shape[0]):
        out[r, :] = False
        low = 0  # samples ≤ threshold in the window around i
        for k in range(min(2 * half, n)):
            low += rows[r, k] <= threshold
        for i in range(half, n - half):
            low += rows[r, i + half] <= threshold
            out[r, i] = low == 0
            low -= rows[r, i - half] <= threshold


def residual_torque_nm(
    current_a: np.ndarray,
    motor_speed_radps: np.ndarray,
    hinge_moment_nm: np.ndarray,
    sample_rate_hz: float,
    drive: DriveConstants,
    derivative_span_s: float = DERIVATIVE_SPAN_S,
) -> np.ndarray:
    """T_R [N·m] at the motor shaft, one value per sample; works on one window or a batch (last axis = time)."""
    current = finite_array("current_a", current_a)
    speed = finite_array("motor_speed_radps", motor_speed_radps)
    hinge = finite_array("hinge_moment_nm", hinge_moment_nm)
    try:  # one window, a batch, or a batch of one signal against one window of the others
        shape = np.broadcast_shapes(current.shape, speed.shape, hinge.shape)
    except ValueError:
        raise InputError(
            "signals", f"shapes differ: current {current.shape}, speed {speed.shape}, hinge {hinge.shape}"
        ) from None
    rate = in_range("sample_rate_hz", sample_rate_hz, 100.0, 1e6, "Hz")
    half = _half_width(speed, rate, derivative_span_s)
    i, w, h = (np.ascontiguousarray(np.broadcast_to(x, shape).reshape(-1, shape[-1])) for x in (current, speed, hinge))
    a = drive
    constants = (a.torque_constant_nm_per_a, a.max_motor_torque_nm, a.gear_ratio, a.inertia_kgm2)
    smoothing, derivative = smoothing_weights(half), derivative_weights(half, rate)
    out = np.empty(i.shape)
    runtime.run_rows(
        lambda r, s: _residual_rows((i[r:s], w[r:s], h[r:s]), (smoothing, derivative), constants, out[r:s]), len(out)
    )
    return out.reshape(shape)
