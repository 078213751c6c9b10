"""Zero-phase IIR low-passes as MATLAB's and SciPy's ``filtfilt`` run them: the digital Butterworth and
Chebyshev type I designs, and the forward-backward filter.

A design starts from the analog prototype's poles (no zeros: both are all-pole low-passes), moves them to the
cutoff pre-warped for the bilinear transform, s = 2·f_s·(z − 1)/(z + 1) with f_s = 2 (frequencies as shares of
the Nyquist rate), which maps each pole p to (4 + p)/(4 − p) and puts the order's zeros at z = −1 (the Nyquist
rate, where a low-pass is deaf). The coefficients are those of the polynomials with these roots.

``filtfilt`` runs the filter forwards then backwards (the phase cancels, the gain is squared), each pass
started in the filter's steady state for its first sample (a step at the start would ring), on the signal
extended at each end by its odd reflection (``padlen`` samples), which continues its level and slope.

Ours rather than ``scipy.signal``'s: importing that package loads ~0.5 s of modules, which every command on a
servo's log paid for these three functions; the tests hold ours to SciPy's.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def butter_lowpass(order: int, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(b, a), each of ``order`` + 1 coefficients: the digital Butterworth low-pass of ``order`` with its −3 dB
    point at ``cutoff`` (a share of the Nyquist rate, in (0, 1)). Its prototype's poles lie evenly on the left
    half of the unit circle: the flattest pass band an all-pole filter of that order has."""
    m = np.arange(-order + 1, order, 2)
    return _digital(-np.exp(1j * np.pi * m / (2 * order)), 1.0, cutoff)


def cheby1_lowpass(order: int, ripple_db: float, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(b, a): the digital Chebyshev type I low-pass of ``order``, its pass band within ``ripple_db`` of unit
    gain up to ``cutoff`` (a share of the Nyquist rate): poles on an ellipse, which buys a steeper fall past the
    cutoff for that ripple. An even order starts the band at the ripple's bottom, 1/√(1 + ε²)."""
    epsilon = np.sqrt(10.0 ** (0.1 * ripple_db) - 1.0)
    mu = np.arcsinh(1.0 / epsilon) / order
    theta = np.pi * np.arange(-order + 1, order, 2) / (2 * order)
    poles = -np.sinh(mu + 1j * theta)
    gain = np.prod(-poles).real
    if order % 2 == 0:
        gain = gain / np.sqrt(1.0 + epsilon * epsilon)
    return _digital(poles, gain, cutoff)


def _digital(poles: np.ndarray, gain: float, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(b, a) of the all-pole analog prototype (``poles``, ``gain``; cutoff 1 rad/s) moved to the pre-warped
    ``cutoff`` and through the bilinear transform (module docstring)."""
    if not 0.0 < cutoff < 1.0:
        raise ValueError(f"cutoff: must be a share of the Nyquist rate in (0, 1), got {cutoff}")
    warped = 4.0 * np.tan(np.pi * cutoff / 2.0)
    poles, gain = poles * warped, gain * warped ** len(poles)
    digital_gain = gain * np.real(1.0 / np.prod(4.0 - poles))
    b = digital_gain * np.poly(-np.ones(len(poles)))
    a = np.poly((4.0 + poles) / (4.0 - poles))
    return np.real(b), np.real(a)


def filtfilt(b: np.ndarray, a: np.ndarray, x: np.ndarray, padlen: int) -> np.ndarray:
    """``x`` (n,) filtered forwards and backwards by (b, a) (of one length, as the designs here give them), its
    ends padded by ``padlen`` samples of odd reflection and each pass started in the filter's steady state (module
    docstring): shape (n,)."""
    if len(b) != len(a):
        raise ValueError(f"b, a: of one length, got {len(b)} and {len(a)}")
    if not 0 <= padlen < len(x):
        raise ValueError(f"padlen: must be below the signal's {len(x)} samples, got {padlen}")
    b, a = np.asarray(b, dtype=float) / a[0], np.asarray(a, dtype=float) / a[0]
    steady = _steady_state(b, a)
    ext = np.concatenate((2.0 * x[0] - x[padlen:0:-1], x, 2.0 * x[-1] - x[-2 : -(padlen + 2) : -1]))  # odd reflection
    forward, backward = np.empty_like(ext), np.empty_like(ext)
    _lfilter(b, a, ext, steady * ext[0], forward)
    _lfilter(b, a, forward[::-1].copy(), steady * forward[-1], backward)
    return backward[::-1][padlen : len(backward) - padlen]


def _steady_state(b: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The delays (len − 1,) of the transposed direct form that a unit input held for ever leaves: z = A·z + B,
    with A the companion matrix of ``a`` (transposed) and B = b[1:] − a[1:]·b[0] (``a[0]`` = 1)."""
    order = len(a) - 1
    companion = np.zeros((order, order))
    companion[:, 0] = -a[1:]
    companion[np.arange(order - 1), np.arange(1, order)] = 1.0
    return np.linalg.solve(np.eye(order) - companion, b[1:] - a[1:] * b[0])


@njit(cache=True)
def _lfilter(b: np.ndarray, a: np.ndarray, x: np.ndarray, z: np.ndarray, y: np.ndarray) -> None:
    """Writes into ``y`` (n,) the IIR filter (b, a) (each (k + 1,), ``a[0]`` = 1) run on ``x`` (n,) from the delays
    ``z`` (k,, updated in place), in the transposed direct form II:

        y[t] = b[0]·x[t] + z[0];   z[i] = b[i+1]·x[t] − a[i+1]·y[t] + z[i+1]   (z[k] = 0)
    """
    order = len(a) - 1
    for t in range(len(x)):
        y[t] = z[0] + b[0] * x[t]
        for i in range(order - 1):
            z[i] = z[i + 1] + x[t] * b[i + 1] - y[t] * a[i + 1]
        z[order - 1] = x[t] * b[order] - y[t] * a[order]
