"""A servo simulated in closed loop: its controller at its own rate, the load between two of its samples.

Each simulation (a lane) follows the window's own set point r_k. At each controller sample k the position
sensor reads q_k = δ·round(x(t_k)/δ + φ) − φ·δ (a sensor of step δ, its phase φ the lane's), the controller
filters it by its FIR taps into q̄_k, differences it into a speed, and holds the force

    F_k = g·sat(kv·(kp·(r_k − q_k) − (q̄_k − q̄_{k−1})/Δt) + e_k, ±u_max)

e_k being a command added to the controller's (an excitation for identification, a feed-forward: the log's
own, ``ema.kinds.servo.log_reading.added_command``; 0 for a loop left to its controller),

until k + 1, over which the load moves by (``ema.model.servo``)

    M·ẍ = F_k − F_load,k − F_offset − F_T(x) − (FDJ + F_S·exp(−(ẋ/v_S)²) − F_P·exp(−s/σ))·sgn(ẋ) − C(ẋ)·ẋ,

s the travel since the motion last reversed (pre-sliding: the friction builds up over the first σ of it), F_T a
force once per turn of the motor, A·sin(2π·x/p) + B·cos(2π·x/p) (p the load's travel per turn),

in ``SUBSTEPS`` steps: the viscous term implicit, a step that would carry ẋ through zero stopping there,
and a load at rest staying there while the net force is within its static level FDJ + F_S (Karnopp). What is
recorded is what the controller's log holds: q_k and F_k.

Lanes are independent: the wrapper runs them in groups on the simulator's thread pool
(``ema.model.runtime``). Parameters per lane, in ``LANE_PARAMETERS`` order: mass [kg], FDJ [N], C up and C
down [N·s/m], the offset [N], the Stribeck excess F_S [N] and speed v_S [m/s], the pre-sliding deficit F_P [N] and
travel σ [m], the turn's force A and B [N] and its period p [m] (0 where a lane has no such effect).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ema.model import runtime
from ema.model.checks import InputError, finite_array

LANE_PARAMETERS = ("mass_kg", "fdj_n", "viscous_up_ns_per_m", "viscous_down_ns_per_m", "offset_n",
                   "stribeck_n", "stribeck_speed_mps", "presliding_n", "presliding_travel_m",
                   "turn_ripple_sin_n", "turn_ripple_cos_n", "turn_ripple_travel_m")  # fmt: skip
SUBSTEPS = 10  # load steps per controller sample: the load's own time constant M/C is hundreds of them
GROUP_LANES = 8  # lanes a pool thread runs at a time


@njit(cache=True, nogil=True)
def _step_load(x, v, net, p, h, travel):  # pragma: no cover - compiled
    """(x, v) after one step h of the load under ``net`` force (drive less load and offset), p a lane's row,
    ``travel`` the distance since the motion last reversed."""
    mass, fdj, c_up, c_down, f_s, v_s, f_p, sigma = p[0], p[1], p[2], p[3], p[5], p[6], p[7], p[8]
    building = f_p * np.exp(-travel / sigma) if sigma > 0.0 else 0.0
    if v == 0.0:
        if abs(net) <= fdj + f_s - building:
            return x, 0.0
        direction = 1.0 if net > 0.0 else -1.0
    else:
        direction = 1.0 if v > 0.0 else -1.0
    coulomb = fdj - building + (f_s * np.exp(-((v / v_s) ** 2)) if v_s > 0.0 else 0.0)
    viscous = c_up if direction > 0.0 else c_down
    v_new = (v + h * (net - coulomb * direction) / mass) / (1.0 + h * viscous / mass)
    if v_new * direction < 0.0:
        v_new = 0.0
    return x + h * v_new, v_new


@njit(cache=True, nogil=True)
def _turn_force(x, p):  # pragma: no cover - compiled
    """F_T(x) [N], the force once per turn of the motor at position x [m], p a lane's row (0 without one)."""
    period = p[11]
    if period <= 0.0:
        return 0.0
    angle = 2.0 * np.pi * x / period
    return p[9] * np.sin(angle) + p[10] * np.cos(angle)


@njit(cache=True, nogil=True)
def run_lanes(
    reference, added, load, controller, taps, params, phase, start, first, count, q_out, f_out
):  # pragma: no cover
    """Simulate lanes [first, first + count) of ``params`` (L, 12) over the reference (N,) [m], the added command
    (N,) [the command's unit] and the load (N,) [N]; ``controller`` = (kp, kv, gain, limit, Δt, δ), ``taps`` (T,),
    ``phase`` (L,), ``start`` = (x0, v0). Writes the recorded position (L, N) [m] and force (L, N) [N]."""
    kp, kv, gain, limit, dt, step = (
        controller[0],
        controller[1],
        controller[2],
        controller[3],
        controller[4],
        controller[5],
    )
    h = dt / SUBSTEPS
    n, n_taps = reference.shape[0], taps.shape[0]
    history = np.empty(n_taps)
    for lane in range(first, first + count):
        p = params[lane]
        x, v = start[0], start[1]
        reversed_at, moving = x, 1.0 if v >= 0.0 else -1.0
        for i in range(n_taps):
            history[i] = x - i * v * dt
        filtered_prev = 0.0
        for i in range(n_taps):
            filtered_prev += taps[i] * (x - (i + 1) * v * dt)
        for k in range(n):
            q = step * np.round(x / step + phase[lane]) - phase[lane] * step if step > 0.0 else x
            for i in range(n_taps - 1, 0, -1):
                history[i] = history[i - 1]
            history[0] = q
            filtered = 0.0
            for i in range(n_taps):
                filtered += taps[i] * history[i]
            u = kv * (kp * (reference[k] - q) - (filtered - filtered_prev) / dt) + added[k]
            u = min(max(u, -limit), limit)
            filtered_prev = filtered
            force = gain * u
            q_out[lane, k] = q
            f_out[lane, k] = force
            net = force - load[k] - p[4]
            for _ in range(SUBSTEPS):
                x, v = _step_load(x, v, net - _turn_force(x, p), p, h, abs(x - reversed_at))
                if v * moving < 0.0:
                    reversed_at, moving = x, -moving


@dataclass(frozen=True)
class ServoLoop:
    """The controller's constants a simulation needs (``ema.model.servo.Servo``, completed by the log)."""

    position_gain_per_s: float  # kp
    speed_gain_per_mps: float  # kv [command unit per m/s]
    drive_gain_n_per_unit: float  # g [N per command unit]
    command_limit: float  # u_max (inf: none)
    period_s: float  # Δt, the controller's sample period
    resolution_m: float  # δ, the position sensor's step (0: exact)
    taps: tuple[float, ...] = (0.5, 0.5)


@dataclass(frozen=True)
class ServoRuns:
    position_m: np.ndarray  # (L, N) as the controller read it
    drive_force_n: np.ndarray  # (L, N) as it commanded it


def simulate_servo(
    set_point_m: np.ndarray,
    params: np.ndarray,
    loop: ServoLoop,
    *,
    load_n: np.ndarray | None = None,
    added_command: np.ndarray | None = None,
    start: tuple[float, float] = (0.0, 0.0),
    phase: np.ndarray | None = None,
) -> ServoRuns:
    """Each row of ``params`` (L, 12: ``LANE_PARAMETERS``) simulated over the set point (N,) in closed loop, with
    ``added_command`` (N,) added to the controller's (none: the controller alone)."""
    reference = finite_array("set_point_m", set_point_m, ndim=1)
    params = np.ascontiguousarray(finite_array("params", params, ndim=2))
    if params.shape[1] != len(LANE_PARAMETERS):
        raise InputError("params", f"has {params.shape[1]} columns, a lane has {len(LANE_PARAMETERS)}")
    if np.any(params[:, 0] <= 0):
        raise InputError("params.mass_kg", "must be positive in every lane")
    lanes, n = params.shape[0], len(reference)
    load = np.zeros(n) if load_n is None else finite_array("load_n", load_n, ndim=1)
    added = np.zeros(n) if added_command is None else finite_array("added_command", added_command, ndim=1)
    if len(load) != n or len(added) != n:
        raise InputError("load_n" if len(load) != n else "added_command", f"must have the set point's {n} samples")
    phases = np.zeros(lanes) if phase is None else finite_array("phase", phase, ndim=1)
    controller = np.array([loop.position_gain_per_s, loop.speed_gain_per_mps, loop.drive_gain_n_per_unit,
                           loop.command_limit, loop.period_s, loop.resolution_m])  # fmt: skip
    q_out, f_out = np.empty((lanes, n)), np.empty((lanes, n))
    taps, first_state = np.asarray(loop.taps, dtype=np.float64), np.asarray(start, dtype=np.float64)

    def run(first: int) -> None:
        count = min(GROUP_LANES, lanes - first)
        run_lanes(reference, added, load, controller, taps, params, phases, first_state, first, count, q_out, f_out)

    runtime.map_on_pool(run, range(0, lanes, GROUP_LANES))
    return ServoRuns(q_out, f_out)
