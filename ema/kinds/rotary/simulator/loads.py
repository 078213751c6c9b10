"""The load the simulator's kernel feels: the F-16's longitudinal dynamics, scaled over the envelope and
discretized exactly, with the hinge moment as their output; a prescribed ground load; a load as logged.

Numbers and scaling rules: ``docs/model.md`` (Stevens & Lewis Example 4.4-1, SI).
The kernel sees the aircraft only through a :class:`LoadModel`: a discrete linear system advanced
once per log interval plus the hinge-moment output, so the on-ground case (a prescribed load) and
a load taken from a log are the same structure with the dynamics switched off.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ema.model.aircraft import FlightCondition, HingeGeometry
from ema.model.checks import InputError, in_range
from ema.model.envelope import DEFAULT_AIRSPEED_MPS

# Linearization at the default condition, x = (ΔV [m/s], Δα [rad], Δθ [rad], Δq [rad/s]), u = Δδe [rad].
A_DEFAULT = np.array(
    [
        [-1.9311e-2, 2.68703, -9.80542, -0.175257],
        [-8.3297e-4, -1.0189, 0.0, 0.90506],
        [0.0, 0.0, 0.0, 1.0],
        [0.0, 0.82225, 0.0, -1.0774],
    ]
)
B_DEFAULT = np.array([3.03345, -0.123180, 0.0, -10.0583])
FT_TO_M = 0.3048
# Trim (V [ft/s], α [deg], δe [deg]); the 502 ft/s row is the default condition's exact trim.
TRIM_TABLE = np.array(
    [
        [300.0, 8.49, -0.591],
        [400.0, 4.16, -0.591],
        [500.0, 2.14, -0.756],
        [DEFAULT_AIRSPEED_MPS / FT_TO_M, np.degrees(0.03691), np.degrees(-0.013244)],
        [600.0, 1.04, -0.846],
        [700.0, 0.382, -0.900],
    ]
)


@dataclass(frozen=True)
class GroundLoad:
    """On-ground routine (Case 1A): the aircraft replaced by a prescribed hinge moment."""

    constant_nm: float = -100.0  # H_e at t = 0 [N·m] on the elevator (negative: pulls towards −δ)
    ramp_nmps: float = 0.0  # dH_e/dt [N·m/s]

    def __post_init__(self) -> None:
        in_range("ground_load.constant_nm", self.constant_nm, -800.0, 800.0, "N·m")
        in_range("ground_load.ramp_nmps", self.ramp_nmps, -2000.0, 2000.0, "N·m/s")


class LoadModel(NamedTuple):
    """What the kernel needs to compute the hinge moment, for flight and ground alike.

    Per log interval: x ← ad·x + bd·(mean δe − trim δe);
    H_e = bias + alpha·clip(alpha_t0 + alpha_t_row·x, ±alpha_t_limit) + ramp·t + delta·δe.
    """

    ad: np.ndarray  # (4, 4) discrete state matrix over one log interval
    bd: np.ndarray  # (4,) discrete input vector [per rad of Δδe]
    trim_elevator_rad: float  # δe_trim [rad]
    alpha_t0_rad: float  # tail angle of attack at trim [rad]
    alpha_t_row: np.ndarray  # (4,) d(α_t)/dx
    alpha_t_limit_rad: float  # |α_t| saturation [rad]
    hinge_bias_nm: float  # q̄·S·c·C_h0, or the ground constant [N·m]
    hinge_alpha_nm: float  # q̄·S·c·C_hα [N·m/rad]
    hinge_delta_nm: float  # q̄·S·c·C_hδ [N·m/rad]
    hinge_ramp_nmps: float  # ground ramp [N·m/s]
    slow_table_nm: np.ndarray  # (K,) the slow part per log interval, from a log; empty: from the model


def state_space(condition: FlightCondition) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) at ``condition``, scaled from the default linearization as ``docs/model.md`` sets out."""
    k_rho = condition.density_ratio
    k_v = k_rho * condition.airspeed_mps / DEFAULT_AIRSPEED_MPS
    k_q = k_rho * (condition.airspeed_mps / DEFAULT_AIRSPEED_MPS) ** 2
    a, b = A_DEFAULT.copy(), B_DEFAULT.copy()
    a[3, 1] *= k_q
    b[3] *= k_q
    a[1, 1] *= k_v
    a[3, 3] *= k_v
    b[1] *= k_v
    # -2g/V² scaled from its tabulated value so that the default condition is reproduced exactly.
    a[1, 0] = A_DEFAULT[1, 0] * (DEFAULT_AIRSPEED_MPS / condition.airspeed_mps) ** 2
    a[1, 3] = 1.0 - (1.0 - A_DEFAULT[1, 3]) * k_rho
    return a, b


def trim(condition: FlightCondition) -> tuple[float, float]:
    """(α_trim, δe_trim) [rad], interpolated at the equivalent airspeed.

    Lift must equal weight, so trim α follows dynamic pressure: looking the table up at the
    equivalent airspeed V·sqrt(ρ/ρ0) carries the sea-level table to altitude. Outside the table's
    300–700 ft/s the end rows hold (the linear model is not valid beyond them anyway).
    """
    eas_ftps = condition.airspeed_mps * np.sqrt(condition.density_ratio) / FT_TO_M
    alpha_deg = np.interp(eas_ftps, TRIM_TABLE[:, 0], TRIM_TABLE[:, 1])
    delta_deg = np.interp(eas_ftps, TRIM_TABLE[:, 0], TRIM_TABLE[:, 2])
    return float(np.radians(alpha_deg)), float(np.radians(delta_deg))


def expm(matrix: np.ndarray) -> np.ndarray:
    """Matrix exponential by scaling and squaring of a Taylor series (small, well-scaled matrices)."""
    norm = np.linalg.norm(matrix, ord=1)
    squarings = max(0, int(np.ceil(np.log2(norm / 0.25))) if norm > 0 else 0)
    scaled = matrix / 2.0**squarings
    result = np.eye(len(matrix))
    term = np.eye(len(matrix))
    for k in range(1, 20):
        term = term @ scaled / k
        result = result + term
    for _ in range(squarings):
        result = result @ result
    return result


def discretize(a: np.ndarray, b: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization: (e^{A·dt}, ∫₀^dt e^{A·τ} dτ · B)."""
    n = len(a)
    augmented = np.zeros((n + 1, n + 1))
    augmented[:n, :n] = a
    augmented[:n, n] = b
    phi = expm(augmented * dt_s)
    return phi[:n, :n], phi[:n, n]


def flight_load_model(
    condition: FlightCondition, interval_s: float, hinge: HingeGeometry = HingeGeometry()
) -> LoadModel:
    """The aircraft at ``condition``, advanced every ``interval_s`` seconds."""
    a, b = state_space(condition)
    ad, bd = discretize(a, b, interval_s)
    alpha_trim, delta_trim = trim(condition)
    scale = hinge.scale_nm(condition)
    lift_slope = 1.0 - hinge.downwash_gradient
    return LoadModel(
        ad=ad,
        bd=bd,
        trim_elevator_rad=delta_trim,
        alpha_t0_rad=lift_slope * alpha_trim,
        alpha_t_row=np.array([0.0, lift_slope, 0.0, hinge.tail_arm_m / condition.airspeed_mps]),
        alpha_t_limit_rad=hinge.alpha_t_limit_rad,
        hinge_bias_nm=scale * hinge.ch0,
        hinge_alpha_nm=scale * hinge.ch_alpha_per_rad,
        hinge_delta_nm=scale * hinge.ch_delta_per_rad,
        hinge_ramp_nmps=0.0,
        slow_table_nm=np.zeros(0),
    )


def _without_aircraft(
    bias_nm: float = 0.0, delta_nm: float = 0.0, ramp_nmps: float = 0.0, table_nm: np.ndarray | None = None
) -> LoadModel:
    """A load with the aircraft's dynamics switched off: H_e = bias + ramp·t (+ table) + delta·δe."""
    return LoadModel(
        ad=np.eye(4),
        bd=np.zeros(4),
        trim_elevator_rad=0.0,
        alpha_t0_rad=0.0,
        alpha_t_row=np.zeros(4),
        alpha_t_limit_rad=1.0,
        hinge_bias_nm=bias_nm,
        hinge_alpha_nm=0.0,
        hinge_delta_nm=delta_nm,
        hinge_ramp_nmps=ramp_nmps,
        slow_table_nm=np.zeros(0) if table_nm is None else np.ascontiguousarray(table_nm),
    )


def ground_load_model(load: GroundLoad) -> LoadModel:
    """A prescribed load: no aircraft states, H_e = constant + ramp·t."""
    return _without_aircraft(bias_nm=load.constant_nm, ramp_nmps=load.ramp_nmps)


@dataclass(frozen=True)
class LoggedLoad:
    """The hinge moment a window logged, driving its simulations in place of the aircraft model.

    Per log interval the simulated moment is H_logged + q̄·S·c·C_hδ·(θ_sim − θ_logged): what the
    aircraft really did, corrected to first order for the simulation's own deflection. Nothing is
    assumed about the aircraft's state when the window starts (a window cut from a flight is
    rarely at trim), and a flight condition enters only through q̄. On the ground (``condition``
    None), or without an airframe's ``hinge`` model, the moment is the logged one as it was: a load
    cell's load follows time, not the deflection. Arrays are (K,), one value per log interval,
    already smoothed of sensor noise by the caller.
    """

    condition: FlightCondition | None
    hinge_moment_nm: np.ndarray  # H_e logged [N·m]
    position_deg: np.ndarray  # θ_u logged [deg]
    hinge: HingeGeometry | None = None

    def __post_init__(self) -> None:
        if self.hinge_moment_nm.shape != self.position_deg.shape or self.hinge_moment_nm.ndim != 1:
            raise InputError("load", "hinge_moment_nm and position_deg must be (K,) arrays of one length")


def logged_load_model(load: LoggedLoad) -> LoadModel:
    """The slow part of the moment, per interval, from the log; the δ term from the condition (none on the
    ground or without an airframe)."""
    flying = load.condition is not None and load.hinge is not None
    delta_nm = load.hinge.per_deflection_nm_per_rad(load.condition) if flying else 0.0  # type: ignore[union-attr,arg-type]
    return _without_aircraft(
        delta_nm=delta_nm, table_nm=load.hinge_moment_nm - delta_nm * np.radians(load.position_deg)
    )


Load = FlightCondition | GroundLoad | LoggedLoad


def load_model(load: Load, interval_s: float, hinge: HingeGeometry | None = None) -> LoadModel:
    """Dispatch on the kind of load: in flight (the airframe's ``hinge`` model, the thesis's elevator by
    default), on ground, or as logged."""
    if isinstance(load, FlightCondition):
        return flight_load_model(load, interval_s, hinge or HingeGeometry())
    if isinstance(load, GroundLoad):
        return ground_load_model(load)
    if isinstance(load, LoggedLoad):
        return logged_load_model(load)
    raise InputError("load", f"must be a FlightCondition, GroundLoad or LoggedLoad, got {type(load).__name__}")
