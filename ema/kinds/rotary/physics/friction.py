"""A physics estimator with no simulation and no network: Eq. 5.1 solved by least squares.

While sliding, the residual torque is T_R = sgn(ω)·(FDJ + k·|T_ext|) + C·ω with k = 1 − η_A when
the load aids the motion and 1/η_O − 1 when it opposes it (T_ext = H_e / n). Both sides go
through the same smoothing kernel as the reconstruction (``simulator.residual``), which keeps the
model linear in FDJ and k: with t = sgn(ω)·(T_R − C·ω), a and o the smoothed aiding and opposing
|T_ext|, t = FDJ + k_aid·a + k_opp·o. η_A is tied to η_O by Eq. 3.4, so the solution is a search over
η_O with FDJ in closed form at each point (``ema.kinds.rotary.physics.eta_search``). Where asked, nuisances
join FDJ in that closed form (``nuisance_columns``): a constant torque c (a sensor off zero,
``ema.kinds.rotary.prepare.departures.zero_offset``), a change ΔC of the viscous coefficient
(``ema.kinds.rotary.prepare.departures.viscosity``), a scale γ of the motor torque and a change ΔJ of the
inertia (k_T, a current sensor's gain or J_M off, ``ema.kinds.rotary.prepare.departures.drive_constants``).

Everything the search needs is the matrix of sums Σ z·zᵀ per window, z = (t, a, o, nuisances…, 1)
(ten numbers without nuisances), so a batch of simulated windows is solved at the cost of one pass
over its samples, and a block jackknife (the sums of B contiguous time blocks, each left out in
turn) gives a standard error from the window itself, one that grows when the residual holds
structure the model lacks.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numba import njit

from ema.estimate.profile import ETA_O_SEARCH
from ema.estimate.stats import RESOLUTION_SHARE
from ema.kinds.rotary.evidence import JACKKNIFE_BLOCKS, jackknife_std
from ema.kinds.rotary.physics.eta_search import solve
from ema.kinds.rotary.simulator.residual import (
    DERIVATIVE_SPAN_S,
    END_STOP_MARGIN_DEG,
    above_throughout,
    kernel_samples,
    residual_torque_nm,
    smooth_derivative,
    smoothed,
)
from ema.model.checks import InputError
from ema.model.params import DriveConstants

MIN_SLIDING_KERNELS = 10  # fewer sliding samples than 10 kernel widths: too little motion to solve
NUISANCES = ("offset", "viscous", "torque_scale", "inertia")  # the terms a solution may carry beside FDJ, in this order


@dataclass(frozen=True)
class SolveSettings:
    # sliding: |ω| above this share of the drive's top speed V_max/k_e over a whole kernel, one sign throughout
    # (30 rad/s of the thesis's 638: far past the speed sensor's noise, clear of the stick-slip near rest)
    min_speed_share: float = 0.047
    derivative_span_s: float = DERIVATIVE_SPAN_S
    blocks: int = JACKKNIFE_BLOCKS
    offset: bool = False  # also solve for a constant torque at the shaft (a current or hinge sensor off zero)
    viscous: bool = False  # also solve for a change ΔC of the viscous coefficient (C·|ω| beyond the document's)
    torque_scale: bool = False  # also solve for γ, the motor torque per logged k_T·I beyond 1 (k_T or a gain off)
    inertia: bool = False  # also solve for ΔJ, the inertia at the motor shaft beyond the actuator's J_M

    def __post_init__(self) -> None:
        if not 0 < self.min_speed_share < 1:
            raise InputError("min_speed_share", f"must be in (0, 1), got {self.min_speed_share}")
        if not 2 <= self.blocks <= 100:
            raise InputError("blocks", f"must be in [2, 100], got {self.blocks}")

    @property
    def nuisances(self) -> tuple[str, ...]:
        return tuple(name for name in NUISANCES if getattr(self, name))

    def sliding_speed_radps(self, drive: DriveConstants) -> float:
        """The |ω| past which the shaft slides, for Eq. 5.1, on ``drive``."""
        return self.min_speed_share * drive.max_motor_speed_radps


SOLUTION_ARRAYS = (
    "fdj_nm",
    "eta_o",
    "fdj_std_nm",
    "eta_o_std",
    "terms",
    "term_stds",
    "residual_rms_nm",
    "resolution_nm",
    "n_sliding",
    "at_search_edge",
)


@dataclass(frozen=True)
class FrictionSolution:
    """Per window (arrays of one length): the estimates, their jackknife std, the solution's quality."""

    fdj_nm: np.ndarray
    eta_o: np.ndarray
    fdj_std_nm: np.ndarray
    eta_o_std: np.ndarray
    # (N, len(NUISANCES)), 0 where not solved: the constant torque c [N·m] at the shaft T_R holds beyond
    # friction, ΔC [N·m·s/rad] beyond the actuator's C, γ (the motor's torque is (1 + γ)·k_T·I where
    # unsaturated), ΔJ [kg·m²] beyond the actuator's J_M
    terms: np.ndarray
    term_stds: np.ndarray
    residual_rms_nm: np.ndarray  # RMS equation error over the sliding samples
    resolution_nm: np.ndarray  # the error the model does not resolve: RESOLUTION_SHARE of k_T·I's RMS there
    n_sliding: np.ndarray  # samples used
    at_search_edge: np.ndarray  # η_O at an end of ETA_O_SEARCH: a bound, not an estimate

    def term(self, name: str) -> np.ndarray:
        """The nuisance ``name``'s solved value per window (its unit: ``terms``)."""
        return self.terms[:, NUISANCES.index(name)]

    def term_std(self, name: str) -> np.ndarray:
        return self.term_stds[:, NUISANCES.index(name)]

    def values(self, row: int | slice = 0) -> dict[str, np.ndarray]:
        """FDJ and η_O of window ``row`` (or rows), keyed as the targets are."""
        return {"FDJ": self.fdj_nm[row], "eta_O": self.eta_o[row]}


def sliding_mask(
    signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants, settings: SolveSettings = SolveSettings()
) -> np.ndarray:
    """The samples Eq. 5.1 reads, shaped as the speed given ((n,) or (N, n)): the shaft past the sliding speed
    throughout a reconstruction kernel (one sign of the speed, so one sign of its friction), away from the end
    stops. Every rule that counts or weighs sliding samples reads this one."""
    speed = np.asarray(signals["motor_speed_radps"])
    width = kernel_samples(rate, settings.derivative_span_s)
    mask = above_throughout(np.abs(np.atleast_2d(speed)), settings.sliding_speed_radps(drive), width)
    mask &= np.abs(np.atleast_2d(signals["position_deg"])) < drive.end_stop_deg - END_STOP_MARGIN_DEG
    return mask if speed.ndim > 1 else mask[0]


def regressors(
    signals: Mapping[str, np.ndarray],
    rate: float,
    drive: DriveConstants,
    settings: SolveSettings,
    residual_nm: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(t, a, o, sliding mask), each (N, n): the linear model's target, aiding and opposing columns.

    ``residual_nm`` is T_R of these signals when the caller has reconstructed it already.
    """
    span_s = settings.derivative_span_s
    speed = np.atleast_2d(signals["motor_speed_radps"])
    if residual_nm is None:
        current, hinge = np.atleast_2d(signals["current_a"]), np.atleast_2d(signals["hinge_moment_nm"])
        residual_nm = residual_torque_nm(current, speed, hinge, rate, drive, span_s)
    residual = np.atleast_2d(residual_nm)
    load = smoothed(np.atleast_2d(signals["hinge_moment_nm"]) / drive.gear_ratio, rate, span_s)
    sliding = np.atleast_2d(sliding_mask(signals, rate, drive, settings))
    direction = np.sign(speed)
    aiding = load * direction > 0
    aid = smoothed(np.abs(load) * aiding, rate, span_s)
    opp = smoothed(np.abs(load) * ~aiding, rate, span_s)
    target = direction * (residual - drive.viscous_nms * smoothed(speed, rate, span_s))
    return target, aid, opp, sliding


def nuisance_columns(
    signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants, settings: SolveSettings
) -> list[np.ndarray]:
    """The columns of ``settings.nuisances``, each (N, n) and, like the target, signed by the direction s:
    s itself (a constant torque), |ω| smoothed (ΔC), −k_T·I smoothed where the motor is not saturated (γ:
    T_R misses γ·k_T·I there; where k_T·I is cut at the peak torque, it misses nothing), and the
    reconstruction's dω/dt (ΔJ: T_R holds ΔJ·dω/dt too much)."""
    span_s, peak = settings.derivative_span_s, drive.max_motor_torque_nm
    speed = np.atleast_2d(signals["motor_speed_radps"])
    direction = np.sign(speed)
    motor = drive.torque_constant_nm_per_a * np.atleast_2d(signals["current_a"])
    columns = {
        "offset": lambda: direction,
        "viscous": lambda: direction * smoothed(speed, rate, span_s),
        "torque_scale": lambda: -direction * smoothed(motor * (np.abs(motor) < peak), rate, span_s),
        "inertia": lambda: direction * smooth_derivative(speed, rate, span_s),
    }
    return [columns[name]() for name in settings.nuisances]


def block_statistics(columns: list[np.ndarray], mask: np.ndarray, blocks: int) -> np.ndarray:
    """(N, blocks, P, P) with P = K + 1: per contiguous time block, Σ z·zᵀ over the masked samples, z the
    K ``columns`` (each (N, n): t, a, o, then the nuisances') and a constant 1 last (its entry: the count)."""
    *columns, mask = (np.ascontiguousarray(c) for c in np.broadcast_arrays(*columns, mask))
    edges = np.linspace(0, mask.shape[-1], blocks + 1).astype(np.int64)
    out = np.zeros((mask.shape[0], blocks, len(columns) + 1, len(columns) + 1))
    _block_sums(tuple(np.asarray(c, dtype=np.float64) for c in columns), mask, edges, out)  # a tuple: no copy
    return out + np.triu(out, 1).swapaxes(-1, -2)


@njit(cache=True, nogil=True)
def _block_sums(columns, mask, edges, out):
    """out[r, b, i, j] (i ≤ j) = Σ over masked samples k of block b of z_i·z_j, z = (columns[…][r, k], 1)."""
    k_cols = len(columns)
    for r in range(mask.shape[0]):
        for b in range(edges.shape[0] - 1):
            for k in range(edges[b], edges[b + 1]):
                if mask[r, k]:
                    for i in range(k_cols):
                        x = columns[i][r, k]
                        for j in range(i, k_cols):
                            out[r, b, i, j] += x * columns[j][r, k]
                        out[r, b, i, k_cols] += x
                    out[r, b, k_cols, k_cols] += 1.0


def solve_friction(
    signals: Mapping[str, np.ndarray],
    rate: float,
    drive: DriveConstants,
    settings: SolveSettings = SolveSettings(),
    residual_nm: np.ndarray | None = None,
) -> FrictionSolution:
    """Solve every window of a batch (signals (N, n), or (n,) for one; or one signal (N, n) against the
    others of one window, each (n,)); windows with too little sliding motion get NaN (``solve_window``
    turns that into an error naming the signals)."""
    t, a, o, mask = regressors(signals, rate, drive, settings, residual_nm)
    columns = [t, a, o, *nuisance_columns(signals, rate, drive, settings)]
    blocks = block_statistics(columns, mask, settings.blocks)  # (N, B, P, P)
    total = blocks.sum(axis=1)
    model = (drive.gear_ratio, settings.nuisances)
    beta, eta_o, sse = solve(total, *model)
    left_out = (total[:, None] - blocks).reshape(-1, *total.shape[1:])
    beta_b, eta_b = (x.reshape(len(total), blocks.shape[1], -1) for x in solve(left_out, *model)[:2])
    std = jackknife_std(beta_b)
    eta_o_std = jackknife_std(eta_b[..., 0])
    enough = total[:, -1, -1] >= MIN_SLIDING_KERNELS * kernel_samples(rate, settings.derivative_span_s)
    nan = np.where(enough, 1.0, np.nan)
    terms, term_stds = np.zeros((2, len(total), len(NUISANCES)))
    for i, name in enumerate(settings.nuisances, start=1):
        terms[:, NUISANCES.index(name)], term_stds[:, NUISANCES.index(name)] = beta[:, i], std[:, i]
    edge = (eta_o <= ETA_O_SEARCH[0] + 1e-4) | (eta_o >= ETA_O_SEARCH[1] - 1e-4)
    return FrictionSolution(
        fdj_nm=beta[:, 0] * nan,
        eta_o=eta_o * nan,
        fdj_std_nm=std[:, 0] * nan,
        eta_o_std=eta_o_std * nan,
        terms=terms * nan[:, None],
        term_stds=term_stds * nan[:, None],
        residual_rms_nm=np.sqrt(np.maximum(sse, 0.0) / np.maximum(total[:, -1, -1], 1.0)) * nan,
        resolution_nm=RESOLUTION_SHARE * _sliding_rms(drive.torque_constant_nm_per_a * signals["current_a"], mask),
        n_sliding=total[:, -1, -1].astype(np.int64),
        at_search_edge=edge & enough,
    )


def _sliding_rms(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(N,) RMS of ``values`` ((n,) or (N, n)) over each row's ``mask`` (N, n)."""
    squares = np.where(mask, np.atleast_2d(values) ** 2, 0.0).sum(axis=-1)
    return np.sqrt(squares / np.maximum(mask.sum(axis=-1), 1))


def solve_window(signals: Mapping[str, np.ndarray], rate: float, drive: DriveConstants) -> FrictionSolution:
    """One window's solution; a window that never slides long enough is bad input naming its signals."""
    solved = solve_friction(signals, rate, drive)
    if np.isnan(solved.fdj_nm[0]):
        raise InputError(
            "signals",
            f"too little sliding motion to estimate friction: {int(solved.n_sliding[0])} samples with "
            f"|motor speed| > {SolveSettings().sliding_speed_radps(drive):.3g} rad/s away from the end stops "
            "(a held or barely moving elevator carries no friction information)",
        )
    return solved
