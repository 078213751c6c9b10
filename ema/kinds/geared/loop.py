"""A geared servo simulated in closed loop from its logged set point: the firmware's P loop, a DC motor fed from the
supply, a pendulum, and the gear train's Borello friction, one step per logged sample (``ema.model.geared``).

Each simulation (a lane) follows the window's set point, read the lane's command delay τ_d late (r_k the logged set
point at t_k − τ_d, linearly between its samples, its first before it). At sample k, of length Δt, the firmware
reads the position q and applies the duty

    d = sat(kp·g·(r_k − q) + d₀·sgn(r_k − q), ±d_max),

the motor gives τ_m = b·V_k·d − k_e·q̇ at the output (b = k_t/R, k_e = k_t²/R; 0 where the motor is off), the load
pulls τ_g = −M_g·sin q (M_g = g·(m·l + μ·l²/2)), and the shaft of inertia J (the servo's and the load's) steps as
Rhoban's BAM steps it:

    τ = τ_m + τ_g,   τ_stop = J·q̇/Δt + τ,
    F = FDJ + (1/η_O − 1)·|τ_g| where the load opposes the motion (τ_g·s < 0, s = sgn q̇, or sgn τ at rest),
    F = FDJ + (1 − η_A)·|τ_g| where it aids it,   F·FSD at rest,
    τ_f = −sgn(τ_stop)·min(|τ_stop|, F + C·|q̇|),
    q̈ = (τ + τ_f)/J,   q̇ ← q̇ + q̈·Δt,   q ← q + q̇·Δt + q̈·Δt²/2,

a friction that can stop the shaft within the step holding it at rest (q̇ = 0 exactly; q then moves by the step's
q̈·Δt²/2, as BAM's does). What is recorded is q at the start of each sample and the duty applied over it.

Parameters per lane, in ``LANE_PARAMETERS`` order: b [N·m/V], k_e [N·m·s/rad], J_servo [kg·m²], g [1/rad], d_max,
d₀, FDJ [N·m], C [N·m·s/rad], k_opp = 1/η_O − 1, k_aid = 1 − η_A, FSD, τ_d [s]. Lanes run in groups on the
simulator's thread pool (``ema.model.runtime``); the runs of many windows at one lane (a calibration's) are packed
end to end (``Packed``) and run in as many slices as the pool has threads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ema.model import runtime
from ema.model.checks import InputError, finite_array

LANE_PARAMETERS = ("torque_per_volt", "back_emf", "inertia_kg_m2", "error_gain_per_rad", "duty_limit", "min_duty",
                   "fdj_nm", "viscous_nm_s_per_rad", "k_opp", "k_aid", "static_friction_ratio",
                   "command_delay_s")  # fmt: skip
GRAVITY = 9.80665  # m/s², the standard value
GROUP_LANES = 8  # lanes a pool thread runs at a time


@dataclass(frozen=True)
class Run:
    """What a window gives its simulation: its set point r (N,), motor switch (N,), supply [V] (N,), its gain kp, its
    sample step Δt [s], its load's gravity moment M_g [N·m] and inertia [kg·m²], and its first position [rad]."""

    set_point_rad: np.ndarray
    motor_on: np.ndarray
    supply_v: np.ndarray
    position_gain: float
    step_s: float
    load_moment_nm: float
    load_inertia_kg_m2: float
    first_position_rad: float


@dataclass(frozen=True)
class Runs:
    position_rad: np.ndarray  # (L, N) at the start of each sample
    duty_ratio: np.ndarray  # (L, N) applied over it


@njit(cache=True, nogil=True)
def _lane(r, on, supply, kp, dt, moment, load_inertia, q0, p, q_out, d_out):  # pragma: no cover - compiled
    """One lane over the run: ``q_out`` and ``d_out`` (N,) filled (module docstring)."""
    b, k_e, j_servo, gain, d_max, d_min, fdj, c, k_opp, k_aid, fsd, delay = (
        p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11])  # fmt: skip
    inertia, lag = j_servo + load_inertia, delay / dt
    q, v = q0, 0.0
    for k in range(len(r)):
        q_out[k] = q
        at = k - lag  # where the set point reaching the loop now was logged, in samples
        if at <= 0.0:
            reference = r[0]
        else:
            i = int(at)
            reference = r[i] + (at - i) * (r[min(i + 1, len(r) - 1)] - r[i])
        error = reference - q
        duty = kp * gain * error + (d_min if error > 0.0 else -d_min if error < 0.0 else 0.0)
        duty = min(max(duty, -d_max), d_max)
        d_out[k] = duty
        tau_m = b * supply[k] * duty - k_e * v if on[k] else 0.0
        tau_g = -moment * np.sin(q)
        tau = tau_m + tau_g
        stop = inertia * v / dt + tau
        way = np.sign(v) if v != 0.0 else np.sign(tau)
        friction = fdj + (k_opp if tau_g * way < 0.0 else k_aid) * abs(tau_g)
        budget = (friction * fsd if v == 0.0 else friction) + c * abs(v)
        held = abs(stop) <= budget
        acc = (tau - np.sign(stop) * min(abs(stop), budget)) / inertia
        v = 0.0 if held else v + acc * dt  # a friction that stops the shaft within the step holds it at rest
        q += v * dt + 0.5 * acc * dt * dt


@njit(cache=True, nogil=True)
def run_lanes(r, on, supply, kp, dt, moment, load_inertia, q0, params, first, count, q_out, d_out):  # pragma: no cover
    """Lanes ``first`` .. ``first + count`` of ``params`` (L, P) over one run, into ``q_out``, ``d_out`` (L, N)."""
    for lane in range(first, first + count):
        _lane(r, on, supply, kp, dt, moment, load_inertia, q0, params[lane], q_out[lane], d_out[lane])


@njit(cache=True, nogil=True)
def run_packed(r, on, supply, starts, scalars, p, first, count, q_out, d_out):  # pragma: no cover - compiled
    """Runs ``first`` .. ``first + count`` of a packing (``Packed``) at one lane ``p``, into the flat outputs."""
    for i in range(first, first + count):
        a, z = starts[i], starts[i + 1]
        kp, dt, moment, load_inertia, q0 = scalars[i, 0], scalars[i, 1], scalars[i, 2], scalars[i, 3], scalars[i, 4]
        _lane(r[a:z], on[a:z], supply[a:z], kp, dt, moment, load_inertia, q0, p, q_out[a:z], d_out[a:z])


def _checked(run: Run, params: np.ndarray) -> np.ndarray:
    reference = finite_array("set_point_rad", run.set_point_rad, ndim=1)
    for name in ("motor_on", "supply_v"):
        if len(getattr(run, name)) != len(reference):
            raise InputError(name, f"must have the set point's {len(reference)} samples")
    params = np.ascontiguousarray(finite_array("params", params, ndim=2))
    if params.shape[1] != len(LANE_PARAMETERS):
        raise InputError("params", f"has {params.shape[1]} columns, a lane has {len(LANE_PARAMETERS)}")
    if np.any(params[:, 2] + run.load_inertia_kg_m2 <= 0) or run.step_s <= 0:
        raise InputError("params.inertia_kg_m2", "the shaft's inertia and the step must be positive in every lane")
    return params


def simulate_lanes(run: Run, params: np.ndarray) -> Runs:
    """Each row of ``params`` (L, ``LANE_PARAMETERS``) simulated over ``run`` in closed loop: positions and duties
    (L, N)."""
    params = _checked(run, params)
    lanes, n = params.shape[0], len(run.set_point_rad)
    q_out, d_out = np.empty((lanes, n)), np.empty((lanes, n))
    arrays = (
        np.ascontiguousarray(run.set_point_rad, dtype=np.float64),
        np.ascontiguousarray(run.motor_on, dtype=np.bool_),
        np.ascontiguousarray(run.supply_v, dtype=np.float64),
    )
    scalars = (float(run.position_gain), float(run.step_s), float(run.load_moment_nm))
    rest = (float(run.load_inertia_kg_m2), float(run.first_position_rad))

    def lanes_from(first: int) -> None:
        run_lanes(*arrays, *scalars, *rest, params, first, min(GROUP_LANES, lanes - first), q_out, d_out)

    runtime.map_on_pool(lanes_from, range(0, lanes, GROUP_LANES))
    return Runs(q_out, d_out)


@dataclass(frozen=True)
class Packed:
    """Many runs end to end: their set points, switches and supplies (T,), where each starts (R + 1,), and each
    one's kp, Δt, M_g, load inertia and first position (R, 5)."""

    set_point_rad: np.ndarray
    motor_on: np.ndarray
    supply_v: np.ndarray
    starts: np.ndarray
    scalars: np.ndarray

    def split(self, flat: np.ndarray) -> list[np.ndarray]:
        """A flat (T,) array cut back into its runs."""
        return [flat[a:z] for a, z in zip(self.starts[:-1], self.starts[1:], strict=True)]


def pack(runs: list[Run]) -> Packed:
    """``runs`` end to end (``Packed``), each checked as a lane's run is."""
    for run in runs:
        _checked(run, np.zeros((1, len(LANE_PARAMETERS))) + 1.0)
    lengths = [len(run.set_point_rad) for run in runs]
    scalars = [
        (run.position_gain, run.step_s, run.load_moment_nm, run.load_inertia_kg_m2, run.first_position_rad)
        for run in runs
    ]
    return Packed(
        np.concatenate([run.set_point_rad for run in runs]).astype(np.float64),
        np.concatenate([run.motor_on for run in runs]).astype(np.bool_),
        np.concatenate([run.supply_v for run in runs]).astype(np.float64),
        np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
        np.array(scalars, dtype=np.float64).reshape(len(runs), 5),
    )


def simulate_packed(packed: Packed, lane: np.ndarray) -> np.ndarray:
    """Every packed run simulated at one lane (``LANE_PARAMETERS``): the positions end to end (T,), the runs
    shared out over the simulator's pool in as many slices as it has threads."""
    p = np.ascontiguousarray(finite_array("lane", lane, ndim=1), dtype=np.float64)
    if len(p) != len(LANE_PARAMETERS):
        raise InputError("lane", f"has {len(p)} parameters, a lane has {len(LANE_PARAMETERS)}")
    q_out, d_out = np.empty(len(packed.set_point_rad)), np.empty(len(packed.set_point_rad))
    count = len(packed.starts) - 1
    share = -(-count // max(runtime.threads(), 1))

    def runs_from(first: int) -> None:
        run_packed(packed.set_point_rad, packed.motor_on, packed.supply_v, packed.starts, packed.scalars, p,
                   first, min(share, count - first), q_out, d_out)  # fmt: skip

    runtime.map_on_pool(runs_from, range(0, count, share))
    return q_out


def lane_plain(run: Run, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The same lane in plain Python, line by line the kernel's math (the test that the fast path equals it)."""
    b, k_e, j_servo, gain, d_max, d_min, fdj, c, k_opp, k_aid, fsd, delay = (float(x) for x in p)
    inertia, dt = j_servo + run.load_inertia_kg_m2, run.step_s
    q, v = run.first_position_rad, 0.0
    positions, duties = [], []
    times = np.arange(len(run.set_point_rad)) * dt
    late = np.interp(times - delay, times, run.set_point_rad)  # the set point as it reaches the loop
    for r, on, supply in zip(late, run.motor_on, run.supply_v, strict=True):
        positions.append(q)
        error = r - q
        duty = min(max(kp_duty(run.position_gain, gain, d_min, error), -d_max), d_max)
        duties.append(duty)
        tau_g = -run.load_moment_nm * np.sin(q)
        tau = (b * supply * duty - k_e * v if on else 0.0) + tau_g
        stop = inertia * v / dt + tau
        way = np.sign(v) if v != 0.0 else np.sign(tau)
        opposing = tau_g * way < 0.0
        friction = fdj + (k_opp if opposing else k_aid) * abs(tau_g)
        budget = (friction * fsd if v == 0.0 else friction) + c * abs(v)
        held = abs(stop) <= budget
        acc = (tau - np.sign(stop) * min(abs(stop), budget)) / inertia
        v = 0.0 if held else v + acc * dt
        q += v * dt + 0.5 * acc * dt * dt
    return np.array(positions), np.array(duties)


def kp_duty(kp: float, gain: float, min_duty: float, error: float) -> float:
    """The firmware's duty before its limit: kp·g·e, plus d₀ the way the error points."""
    return kp * gain * error + float(np.sign(error)) * min_duty
