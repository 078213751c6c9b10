"""A physics estimator with no simulation and no network: Eq. 5.1 fitted by least squares.

While sliding, the residual torque is T_R = sgn(ω)·(FDJ + k·|T_ext|) + C·ω with k = 1 − η_A when
the load aids the motion and 1/η_O − 1 when it opposes it (T_ext = H_e / n). Both sides go
through the same smoothing kernel as the reconstruction (``sim.residual``), which keeps the
model linear in FDJ and k: with t = sgn(ω)·(T_R − C·ω), a and o the smoothed aiding and opposing
|T_ext|, t = FDJ + k_aid·a + k_opp·o. η_A is tied to η_O by Eq. 3.4, so the fit is a search over
η_O with FDJ in closed form at each point.

Everything the search needs is ten sums per window (m, Σt, Σa, Σo and their products), so a
batch of simulated windows is fitted at the cost of one pass over its samples, and a block
jackknife (the sums of B contiguous time blocks, each left out in turn) gives a standard error
from the window itself: one that grows when the residual holds structure the model lacks.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numba import njit

from sim.checks import InputError
from sim.params import ActuatorParams, eta_a_from_eta_o
from sim.residual import (
    DEFAULT_DERIVATIVE_WINDOW_S,
    END_STOP_MARGIN_DEG,
    above_throughout,
    kernel_samples,
    residual_torque_nm,
    smoothed,
)

ETA_O_SEARCH = (0.20, 0.999)  # η_O searched over; Case 1C reaches 0.44
GRID_POINTS = 41
REFINEMENTS = 3  # coarse-to-fine passes: η_O to ~1e-5 (the SSE is smooth and unimodal in η_O)
JACKKNIFE_BLOCKS = 10
MIN_SLIDING_KERNELS = 10  # fewer sliding samples than 10 kernel widths: too little motion to fit
T, A, OPP, TT, AA, OO, TA, TO, AO, M = range(10)  # the sufficient statistics, in this order


@dataclass(frozen=True)
class FitSettings:
    min_speed_radps: float = 30.0  # sliding: |ω| above this over a whole kernel, one sign throughout
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S
    blocks: int = JACKKNIFE_BLOCKS

    def __post_init__(self) -> None:
        if self.min_speed_radps <= 0:
            raise InputError("min_speed_radps", f"must be positive, got {self.min_speed_radps}")
        if not 2 <= self.blocks <= 100:
            raise InputError("blocks", f"must be in [2, 100], got {self.blocks}")


FIT_ARRAYS = ("fdj_nm", "eta_o", "fdj_std_nm", "eta_o_std", "residual_rms_nm", "n_sliding", "at_search_edge")


@dataclass(frozen=True)
class FrictionFit:
    """Per window (arrays of one length): the estimates, their jackknife std, the fit's quality."""

    fdj_nm: np.ndarray
    eta_o: np.ndarray
    fdj_std_nm: np.ndarray
    eta_o_std: np.ndarray
    residual_rms_nm: np.ndarray  # RMS equation error over the sliding samples
    n_sliding: np.ndarray  # samples used
    at_search_edge: np.ndarray  # η_O at an end of ETA_O_SEARCH: a bound, not an estimate

    @property
    def eta_a(self) -> np.ndarray:
        return eta_a_from_eta_o(self.eta_o)


def regressors(
    signals: Mapping[str, np.ndarray],
    rate: float,
    actuator: ActuatorParams,
    settings: FitSettings,
    residual_nm: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(t, a, o, sliding mask), each (N, n): the linear model's target, aiding and opposing columns.

    ``residual_nm`` is T_R of these signals when the caller has reconstructed it already.
    """
    window_s = settings.derivative_window_s
    speed = np.atleast_2d(signals["motor_speed_radps"])
    if residual_nm is None:
        current, hinge = np.atleast_2d(signals["current_a"]), np.atleast_2d(signals["hinge_moment_nm"])
        residual_nm = residual_torque_nm(current, speed, hinge, rate, actuator, window_s)
    residual = np.atleast_2d(residual_nm)
    load = smoothed(np.atleast_2d(signals["hinge_moment_nm"]) / actuator.gear_ratio, rate, window_s)
    width = kernel_samples(rate, window_s)
    sliding = above_throughout(np.abs(speed), settings.min_speed_radps, width)  # one sign over the whole kernel
    sliding &= np.abs(np.atleast_2d(signals["position_deg"])) < actuator.end_stop_deg - END_STOP_MARGIN_DEG
    direction = np.sign(speed)
    aiding = load * direction > 0
    aid = smoothed(np.abs(load) * aiding, rate, window_s)
    opp = smoothed(np.abs(load) * ~aiding, rate, window_s)
    target = direction * (residual - actuator.viscous_nms * smoothed(speed, rate, window_s))
    return target, aid, opp, sliding


def block_statistics(t: np.ndarray, a: np.ndarray, o: np.ndarray, mask: np.ndarray, blocks: int) -> np.ndarray:
    """(N, blocks, 10) sums over the masked samples of each of ``blocks`` contiguous time blocks."""
    edges = np.linspace(0, t.shape[-1], blocks + 1).astype(np.int64)
    out = np.zeros((t.shape[0], blocks, 10))
    _block_sums(t, a, o, mask, edges, out)
    return out


@njit(cache=True, nogil=True)
def _block_sums(t, a, o, mask, edges, out):
    """out[r, b] = Σ over masked samples of block b of (t, a, o, t², a², o², ta, to, ao, 1)."""
    for r in range(t.shape[0]):
        for b in range(edges.shape[0] - 1):
            for i in range(edges[b], edges[b + 1]):
                if mask[r, i]:
                    x, y, z = t[r, i], a[r, i], o[r, i]
                    out[r, b, T] += x
                    out[r, b, A] += y
                    out[r, b, OPP] += z
                    out[r, b, TT] += x * x
                    out[r, b, AA] += y * y
                    out[r, b, OO] += z * z
                    out[r, b, TA] += x * y
                    out[r, b, TO] += x * z
                    out[r, b, AO] += y * z
                    out[r, b, M] += 1.0


def _profile(stats: np.ndarray, eta_o: np.ndarray, gear: float) -> tuple[np.ndarray, np.ndarray]:
    """For stats (R, 10) and a grid per row (R, G): FDJ (R, G) in closed form and the SSE (R, G)."""
    k_opp = 1.0 / eta_o - 1.0
    k_aid = 1.0 - eta_a_from_eta_o(eta_o, gear)
    s = stats[:, :, None]
    m = np.maximum(s[:, M], 1.0)
    fdj = (s[:, T] - k_aid * s[:, A] - k_opp * s[:, OPP]) / m
    sse = (
        s[:, TT] + k_aid**2 * s[:, AA] + k_opp**2 * s[:, OO]
        - 2 * k_aid * s[:, TA] - 2 * k_opp * s[:, TO] + 2 * k_aid * k_opp * s[:, AO]
        - m * fdj**2
    )  # fmt: skip
    return fdj, sse


def solve(stats: np.ndarray, gear: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(FDJ, η_O, SSE) per row of ``stats`` (R, 10): a coarse-to-fine grid over η_O, vectorized."""
    rows = np.arange(len(stats))
    low = np.full(len(stats), ETA_O_SEARCH[0])
    high = np.full(len(stats), ETA_O_SEARCH[1])
    for _ in range(REFINEMENTS):
        grid = low[:, None] + (high - low)[:, None] * np.linspace(0.0, 1.0, GRID_POINTS)
        fdj, sse = _profile(stats, grid, gear)
        best = np.argmin(sse, axis=1)
        step = grid[:, 1] - grid[:, 0]
        centre = grid[rows, best]
        low = np.maximum(centre - step, ETA_O_SEARCH[0])
        high = np.minimum(centre + step, ETA_O_SEARCH[1])
    return fdj[rows, best], centre, sse[rows, best]


def _jackknife_std(estimates: np.ndarray) -> np.ndarray:
    """Std of the full-sample estimate from (N, B) leave-one-block-out estimates."""
    b = estimates.shape[1]
    return np.sqrt((b - 1) / b * np.sum((estimates - estimates.mean(axis=1, keepdims=True)) ** 2, axis=1))


def fit_friction(
    signals: Mapping[str, np.ndarray],
    rate: float,
    actuator: ActuatorParams = ActuatorParams(),
    settings: FitSettings = FitSettings(),
    residual_nm: np.ndarray | None = None,
) -> FrictionFit:
    """Fit every window of a batch (signals (N, n), or (n,) for one; or one signal (N, n) against the
    others of one window, each (n,)); windows with too little sliding motion get NaN (``fit_window``
    turns that into an error naming the signals)."""
    t, a, o, mask = (
        np.ascontiguousarray(c)
        for c in np.broadcast_arrays(*regressors(signals, rate, actuator, settings, residual_nm))
    )
    blocks = block_statistics(t, a, o, mask, settings.blocks)  # (N, B, 10)
    total = blocks.sum(axis=1)
    fdj, eta_o, sse = solve(total, actuator.gear_ratio)
    left_out = (total[:, None, :] - blocks).reshape(-1, 10)
    fdj_b, eta_b, _ = solve(left_out, actuator.gear_ratio)
    n_rows = len(total)
    width = kernel_samples(rate, settings.derivative_window_s)
    enough = total[:, M] >= MIN_SLIDING_KERNELS * width
    nan = np.where(enough, 1.0, np.nan)
    edge = (eta_o <= ETA_O_SEARCH[0] + 1e-4) | (eta_o >= ETA_O_SEARCH[1] - 1e-4)
    return FrictionFit(
        fdj_nm=fdj * nan,
        eta_o=eta_o * nan,
        fdj_std_nm=_jackknife_std(fdj_b.reshape(n_rows, -1)) * nan,
        eta_o_std=_jackknife_std(eta_b.reshape(n_rows, -1)) * nan,
        residual_rms_nm=np.sqrt(np.maximum(sse, 0.0) / np.maximum(total[:, M], 1.0)) * nan,
        n_sliding=total[:, M].astype(np.int64),
        at_search_edge=edge & enough,
    )


def fit_window(
    signals: Mapping[str, np.ndarray], rate: float, actuator: ActuatorParams = ActuatorParams()
) -> FrictionFit:
    """One window's fit; a window that never slides long enough is bad input naming its signals."""
    fitted = fit_friction(signals, rate, actuator)
    if np.isnan(fitted.fdj_nm[0]):
        raise InputError(
            "signals",
            f"too little sliding motion to estimate friction: {int(fitted.n_sliding[0])} samples with "
            f"|motor speed| > {FitSettings().min_speed_radps:g} rad/s away from the end stops "
            "(a held or barely moving elevator carries no friction information)",
        )
    return fitted
