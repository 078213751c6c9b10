"""A physics estimator with no simulation and no network: Eq. 5.1 fitted by least squares.

While sliding, the residual torque is T_R = sgn(ω)·(FDJ + k·|T_ext|) + C·ω with k = 1 − η_A when
the load aids the motion and 1/η_O − 1 when it opposes it (T_ext = H_e / n). Both sides go
through the same smoothing kernel as the reconstruction (``sim.residual``), which keeps the
model linear in FDJ and k: with t = sgn(ω)·(T_R − C·ω), a and o the smoothed aiding and opposing
|T_ext|, t = FDJ + k_aid·a + k_opp·o. η_A is tied to η_O by Eq. 3.4, so the fit is a search over
η_O with FDJ in closed form at each point. Where asked, two nuisances join FDJ in that closed form:
a constant torque c (t gains c·sgn ω: a sensor off zero, ``training.zero_offset``) and a change ΔC of
the viscous coefficient (t gains ΔC·|ω|, ``training.viscosity``).

Everything the search needs is ten sums per window (m, Σt, Σa, Σo and their products; twenty with
the nuisances' columns), so a
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
# The sufficient statistics, in this order; S… are the direction's (s = sgn ω, s² = 1), for the offset,
# V… the speed's (v = |ω| smoothed), for the viscous coefficient.
T, A, OPP, TT, AA, OO, TA, TO, AO, M, S, ST, SA, SO, V, VT, VA, VO, VV, SV = range(20)
N_STATS = 20


@dataclass(frozen=True)
class FitSettings:
    min_speed_radps: float = 30.0  # sliding: |ω| above this over a whole kernel, one sign throughout
    derivative_window_s: float = DEFAULT_DERIVATIVE_WINDOW_S
    blocks: int = JACKKNIFE_BLOCKS
    offset: bool = False  # also fit a constant torque at the shaft (a current or hinge sensor off zero)
    viscous: bool = False  # also fit a change ΔC of the viscous coefficient (C·|ω| beyond the spec's)

    def __post_init__(self) -> None:
        if self.min_speed_radps <= 0:
            raise InputError("min_speed_radps", f"must be positive, got {self.min_speed_radps}")
        if not 2 <= self.blocks <= 100:
            raise InputError("blocks", f"must be in [2, 100], got {self.blocks}")


FIT_ARRAYS = (
    "fdj_nm", "eta_o", "fdj_std_nm", "eta_o_std", "offset_nm", "offset_std_nm", "viscous_nms", "viscous_std_nms",
    "residual_rms_nm", "n_sliding", "at_search_edge",
)  # fmt: skip


@dataclass(frozen=True)
class FrictionFit:
    """Per window (arrays of one length): the estimates, their jackknife std, the fit's quality."""

    fdj_nm: np.ndarray
    eta_o: np.ndarray
    fdj_std_nm: np.ndarray
    eta_o_std: np.ndarray
    offset_nm: np.ndarray  # the constant torque at the shaft T_R holds beyond friction (0 unless fitted)
    offset_std_nm: np.ndarray
    viscous_nms: np.ndarray  # ΔC [N·m·s/rad] beyond the actuator's C (0 unless fitted)
    viscous_std_nms: np.ndarray
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


def block_statistics(
    t: np.ndarray, a: np.ndarray, o: np.ndarray, s: np.ndarray, v: np.ndarray, mask: np.ndarray, blocks: int
) -> np.ndarray:
    """(N, blocks, N_STATS) sums over the masked samples of each of ``blocks`` contiguous time blocks."""
    edges = np.linspace(0, t.shape[-1], blocks + 1).astype(np.int64)
    out = np.zeros((t.shape[0], blocks, N_STATS))
    _block_sums(t, a, o, s, v, mask, edges, out)
    return out


@njit(cache=True, nogil=True)
def _block_sums(t, a, o, s, v, mask, edges, out):
    """out[r, b] = Σ over masked samples of block b of (t, a, o, t², a², o², ta, to, ao, 1, s, st, sa, so,
    v, vt, va, vo, v², sv)."""
    for r in range(t.shape[0]):
        for b in range(edges.shape[0] - 1):
            for i in range(edges[b], edges[b + 1]):
                if mask[r, i]:
                    x, y, z, d, w = t[r, i], a[r, i], o[r, i], s[r, i], v[r, i]
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
                    out[r, b, S] += d
                    out[r, b, ST] += d * x
                    out[r, b, SA] += d * y
                    out[r, b, SO] += d * z
                    out[r, b, V] += w
                    out[r, b, VT] += w * x
                    out[r, b, VA] += w * y
                    out[r, b, VO] += w * z
                    out[r, b, VV] += w * w
                    out[r, b, SV] += d * w


# An offset needs motion both ways: with fewer than this share of the samples in the rarer direction,
# it cannot be told from FDJ and is not fitted. ΔC needs speeds that vary: a coefficient of variation below
# this, and C·|ω| cannot be told from FDJ either.
MIN_OFFSET_BALANCE = 0.05
MIN_SPEED_VARIATION = 0.05


def _nuisances(
    st: np.ndarray, m: np.ndarray, u: tuple[np.ndarray, ...], offset: bool, viscous: bool
) -> tuple[np.ndarray, ...]:
    """(FDJ, c, ΔC, Σ fitted·u) from the normal equations of u ≈ FDJ + c·s + ΔC·v; a term not fitted (not
    asked, or not told from FDJ by this window) gets an identity row, so its value is 0."""
    some = st[:, M] > 0
    use_c = offset & some & (m - np.abs(st[:, S]) >= 2 * MIN_OFFSET_BALANCE * m)  # 2 × the rarer direction's count
    use_d = viscous & some & (st[:, VV] * m - st[:, V] ** 2 > (MIN_SPEED_VARIATION * st[:, V]) ** 2)
    use_c, use_d = np.broadcast_arrays(use_c, use_d, u[0])[:2]
    ridge = 1.0 + 1e-12  # s and v both fitted yet nearly dependent (speeds set by the direction): no singular solve
    gram = np.zeros((*u[0].shape, 3, 3))
    gram[..., 0, 0] = m
    gram[..., 0, 1] = gram[..., 1, 0] = np.where(use_c, st[:, S], 0.0)
    gram[..., 0, 2] = gram[..., 2, 0] = np.where(use_d, st[:, V], 0.0)
    gram[..., 1, 2] = gram[..., 2, 1] = np.where(use_c & use_d, st[:, SV], 0.0)
    gram[..., 1, 1] = np.where(use_c, ridge * m, 1.0)
    gram[..., 2, 2] = np.where(use_d, ridge * st[:, VV], 1.0)
    rhs = np.stack([u[0], np.where(use_c, u[1], 0.0), np.where(use_d, u[2], 0.0)], axis=-1)
    beta = np.linalg.solve(gram, rhs[..., None])[..., 0]
    return beta[..., 0], beta[..., 1], beta[..., 2], np.sum(beta * rhs, axis=-1)


def _profile(stats: np.ndarray, eta_o: np.ndarray, gear: float, offset: bool, viscous: bool) -> tuple[np.ndarray, ...]:
    """For stats (R, N_STATS) and a grid per row (R, G): FDJ, the offset and ΔC (R, G) in closed form, and
    the SSE (R, G). With u = t − k_aid·a − k_opp·o, FDJ is u's mean, or with c·s and ΔC·v its regression on
    them where asked (``_nuisances``)."""
    k_opp = 1.0 / eta_o - 1.0
    k_aid = 1.0 - eta_a_from_eta_o(eta_o, gear)
    st = stats[:, :, None]
    m = np.maximum(st[:, M], 1.0)
    u = st[:, T] - k_aid * st[:, A] - k_opp * st[:, OPP]
    uu = (
        st[:, TT] + k_aid**2 * st[:, AA] + k_opp**2 * st[:, OO]
        - 2 * k_aid * st[:, TA] - 2 * k_opp * st[:, TO] + 2 * k_aid * k_opp * st[:, AO]
    )  # fmt: skip
    if not (offset or viscous):  # the batches of simulations: the plain mean, no solve
        fdj = u / m
        return fdj, np.zeros_like(fdj), np.zeros_like(fdj), uu - fdj * u
    su = st[:, ST] - k_aid * st[:, SA] - k_opp * st[:, SO]
    vu = st[:, VT] - k_aid * st[:, VA] - k_opp * st[:, VO]
    fdj, c, d, explained = _nuisances(st, m, (u, su, vu), offset, viscous)
    return fdj, c, d, uu - explained


def solve(stats: np.ndarray, gear: float, offset: bool = False, viscous: bool = False) -> tuple[np.ndarray, ...]:
    """(FDJ, η_O, offset, ΔC, SSE) per row of ``stats`` (R, N_STATS): a coarse-to-fine grid over η_O, vectorized."""
    rows = np.arange(len(stats))
    low = np.full(len(stats), ETA_O_SEARCH[0])
    high = np.full(len(stats), ETA_O_SEARCH[1])
    for _ in range(REFINEMENTS):
        grid = low[:, None] + (high - low)[:, None] * np.linspace(0.0, 1.0, GRID_POINTS)
        fdj, c, d, sse = _profile(stats, grid, gear, offset, viscous)
        best = np.argmin(sse, axis=1)
        step = grid[:, 1] - grid[:, 0]
        centre = grid[rows, best]
        low = np.maximum(centre - step, ETA_O_SEARCH[0])
        high = np.minimum(centre + step, ETA_O_SEARCH[1])
    return fdj[rows, best], centre, c[rows, best], d[rows, best], sse[rows, best]


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
    t, a, o, mask = regressors(signals, rate, actuator, settings, residual_nm)
    speed = np.atleast_2d(signals["motor_speed_radps"])
    s = np.sign(speed)
    # |ω| as the target reads it, where sliding; only a viscous fit reads it (the batches of simulations do not)
    v = s * smoothed(speed, rate, settings.derivative_window_s) if settings.viscous else np.zeros(1)
    t, a, o, s, v, mask = (np.ascontiguousarray(c) for c in np.broadcast_arrays(t, a, o, s, v, mask))
    blocks = block_statistics(t, a, o, s, v, mask, settings.blocks)  # (N, B, N_STATS)
    total = blocks.sum(axis=1)
    terms = (actuator.gear_ratio, settings.offset, settings.viscous)
    fdj, eta_o, offset, viscous, sse = solve(total, *terms)
    left_out = (total[:, None, :] - blocks).reshape(-1, N_STATS)
    n_rows = len(total)
    fdj_b, eta_b, offset_b, viscous_b = (x.reshape(n_rows, -1) for x in solve(left_out, *terms)[:4])
    width = kernel_samples(rate, settings.derivative_window_s)
    enough = total[:, M] >= MIN_SLIDING_KERNELS * width
    nan = np.where(enough, 1.0, np.nan)
    edge = (eta_o <= ETA_O_SEARCH[0] + 1e-4) | (eta_o >= ETA_O_SEARCH[1] - 1e-4)
    return FrictionFit(
        fdj_nm=fdj * nan,
        eta_o=eta_o * nan,
        fdj_std_nm=_jackknife_std(fdj_b) * nan,
        eta_o_std=_jackknife_std(eta_b) * nan,
        offset_nm=offset * nan,
        offset_std_nm=_jackknife_std(offset_b) * nan,
        viscous_nms=viscous * nan,
        viscous_std_nms=_jackknife_std(viscous_b) * nan,
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
