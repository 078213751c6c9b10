"""The Numba kernels: one 1 µs step of the EMA, and the lock-step loop over groups of simulations.

Pure functions of their arguments: ``simulator.batch`` validates, packs the constants, allocates
``out`` and runs :func:`run_group` for each group of simulations on its own threads. The step is
written once (:func:`advance`) and every loop uses it, so the vectorized lock-step path and the
one-lane path run the same arithmetic. The branches in :func:`advance` are simple enough for
LLVM to turn into selects; that is what lets the lane loop in :func:`_advance_lanes` vectorize
across simulations, three vectors of lanes an iteration once ``ema.model.runtime.configure_simulator`` has run
(*Interleaving* there): a step's dependent chain is long, and three independent ones keep the
core busy. The loop vectorizes only in exactly this form (a loop over a slice of the lanes, or two
lanes an iteration, ran scalar at 3x the cost).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

# Rows of ``out``: recorded signals, each the mean over a log interval.
POSITION, SPEED, CURRENT, HINGE, COMMAND, LOSS = range(6)
N_RECORDED = 6
# Rows of ``initial``: the state every simulation starts from.
INIT_POSITION, INIT_SPEED, INIT_CURRENT = range(3)
# Rows of ``per_sim``: health parameters in the form the friction model uses.
FDJ, FSJ, K_AID, K_OPP = range(4)
# Rows of a group's ``lane`` array. Everything the lane loop touches lives in this one array: with
# separate arrays LLVM needed too many runtime overlap checks and left the loop scalar; with one
# base pointer it vectorizes, and its remaining checks are hoisted out of the step loop.
CURRENT_NOW, SPEED_NOW, ANGLE_NOW, POSITION_NOW = range(4)  # state
LOAD_SLOW, COMMAND0, COMMAND_STEP = range(4, 7)  # inputs, fixed over an interval
COGGING, DRY_DYNAMIC, DRY_STATIC = range(7, 10)  # cogging torque, FDJ / FSJ plus friction effects
LANE_FDJ, LANE_FSJ, LANE_K_AID, LANE_K_OPP = range(10, 14)  # health, copied from per_sim
SUM_POSITION, SUM_SPEED, SUM_CURRENT, SUM_LOSS = range(14, 18)  # running sums over the interval
N_LANE_ROWS = 18


class KernelConstants(NamedTuple):
    """Everything constant over a batch, in the form the step uses (derived once, in simulator.batch)."""

    step_s: float  # h [s]
    step_over_gear: float  # h / n [s]
    position_gain: float  # G_P [1/s]
    max_speed_ref: float  # ω_max [rad/s]
    speed_gain_over_kt: float  # GAP / (k_T nominal · current sensor gain) [A·s/rad], in true amperes
    max_current: float  # I_max / current sensor gain [A], in true amperes
    voltage_step: float  # h·V_max / L [A]
    current_decay: float  # 1 − h·R / L [-]
    back_emf_step: float  # h·k_e / L [A·s/rad], k_e true
    torque_constant: float  # k_T, true [N·m/A]
    max_torque: float  # T_M,max [N·m]
    inverse_gear: float  # 1 / n [-]
    gear: float  # n [-]
    step_over_inertia: float  # h / J_M [s/(kg·m²)]
    viscous: float  # C_M, true [N·m·s/rad]
    half_backlash: float  # BLK / 2 [rad], elevator side
    end_stop: float  # θ_stop [rad]
    current_sensor_gain: float  # measured / true current [-]
    current_sensor_offset: float  # measured − gain·true current [A]
    current_ref_shift: float  # the offset in true amperes (offset / gain) [A]: the loop regulates the measured current
    hinge_sensor_bias: float  # measured − true hinge moment [N·m]
    stribeck_amplitude: float  # extra dry friction at zero speed [N·m]
    stribeck_inverse_speed: float  # 1 / ω_s [s/rad]
    position_friction: float  # extra dry friction per rad of |θ_u| [N·m/rad]
    cogging_amplitude: float  # [N·m]
    cogging_wavenumber: float  # cogging periods per rad of θ_m / n [1/rad]
    cogging_phase: float  # [rad]
    table_variable: int  # extra dry friction tabulated against: 0 none, 1 |ω| [rad/s], 2 θ_u [rad], 3 t [s]
    table_start: float  # first grid point of the table, in its variable's unit
    table_step: float  # grid spacing (the values come apart, as ``table_nm``: an array in here kept LLVM
    # from hoisting the scalars out of the lane loop, and the base model ran 2.7x slower)
    with_friction_effects: bool  # Stribeck, position friction or a table on: update the dry levels every step
    with_cogging: bool  # skip the sine when the effect is off


@njit(cache=True, inline="always", error_model="numpy")
def advance(c, load_delta, command_rad, lane, state):
    """One step h of controller, RL phase, shaft with Borello friction, end stops and backlash.

    ``lane`` = (load_slow, cogging, dry_dynamic, dry_static, k_aid, k_opp): the load torque at the motor shaft
    is ``load_slow + load_delta·position``; ``dry_dynamic`` / ``dry_static`` are the load-independent
    friction levels (FDJ / FSJ plus any friction effect), ``cogging`` the cogging torque (0 when off).
    ``state`` = (current, speed, angle, position): ``angle`` is θ_m / n (the motor angle seen on the
    elevator side), ``position`` the elevator deflection θ_u after the backlash. Returns the new
    (current, speed, angle, position) and the step's transmission loss torque [N·m] (dry + viscous +
    cogging). Written branch-free (selects, min/max) so that a loop over simulations vectorizes;
    constants are pre-folded in ``KernelConstants`` to save operations (the tuples are unpacked where
    the step is inlined: they cost nothing).
    """
    load_slow, cogging, dry_dynamic, dry_static, k_aid, k_opp = lane
    current, speed, angle, position = state
    # Controller: P position loop -> speed reference, P speed loop -> current reference.
    speed_ref = min(max(c.position_gain * (command_rad - position), -c.max_speed_ref), c.max_speed_ref)
    current_ref = min(max(c.speed_gain_over_kt * (speed_ref - speed), -c.max_current), c.max_current)
    current_ref -= c.current_ref_shift
    # PWM-like bang-bang on the measured current; explicit Euler on L·dI/dt = V − R·I − k_e·ω.
    voltage_step = c.voltage_step if current_ref > current else (-c.voltage_step if current_ref < current else 0.0)
    current = c.current_decay * current + voltage_step - c.back_emf_step * speed
    motor_torque = min(max(c.torque_constant * current, -c.max_torque), c.max_torque)

    load = load_slow + load_delta * position  # T_ext = H_e / n
    viscous = c.viscous * speed
    drive = motor_torque + load - viscous - cogging

    # Borello friction: aiding when the load acts along the motion (of the drive when stuck).
    moving = speed != 0.0
    direction_of = speed if moving else drive
    direction = 1.0 if direction_of > 0.0 else (-1.0 if direction_of < 0.0 else 0.0)
    k_load = k_aid if load * direction > 0.0 else k_opp
    load_part = k_load * abs(load)
    stuck = (not moving) & (abs(drive) <= dry_static + load_part)
    friction = drive if stuck else (dry_dynamic + load_part) * direction
    new_speed = speed + c.step_over_inertia * (drive - friction)
    # Slipping through zero stops the shaft; the next step decides stick or slip.
    new_speed = 0.0 if new_speed * speed < 0.0 else new_speed
    loss = friction + viscous + cogging

    # Kinematics: semi-implicit Euler, end stops on the shaft, dead band on the elevator side.
    free_angle = angle + c.step_over_gear * new_speed
    angle = min(max(free_angle, -c.end_stop), c.end_stop)
    new_speed = 0.0 if abs(free_angle) > c.end_stop else new_speed  # only outward motion gets there
    position = min(max(position, angle - c.half_backlash), angle + c.half_backlash)
    return current, new_speed, angle, position, loss


@njit(cache=True)
def _hinge_slow(load, state, time_s):
    """The part of H_e that changes on the aircraft's time scale: trim, α_t, the ground ramp."""
    alpha_t = load.alpha_t0_rad
    for i in range(4):
        alpha_t += load.alpha_t_row[i] * state[i]
    alpha_t = min(max(alpha_t, -load.alpha_t_limit_rad), load.alpha_t_limit_rad)
    return load.hinge_bias_nm + load.hinge_alpha_nm * alpha_t + load.hinge_ramp_nmps * time_s


@njit(cache=True)
def _advance_aircraft(load, state, mean_elevator_rad):
    """x ← Ad·x + Bd·(mean δe − δe_trim): exact ZOH over one log interval."""
    du = mean_elevator_rad - load.trim_elevator_rad
    new = np.empty(4)
    for i in range(4):
        acc = load.bd[i] * du
        for j in range(4):
            acc += load.ad[i, j] * state[j]
        new[i] = acc
    state[:] = new


@njit(cache=True, inline="always", error_model="numpy")
def _tabulated(c, table_nm, x):
    """The friction table at x: linear between grid points, held past the ends."""
    u = min(max((x - c.table_start) / c.table_step, 0.0), table_nm.shape[0] - 1.0)
    i = min(int(u), table_nm.shape[0] - 2)
    f = u - i
    return table_nm[i] * (1.0 - f) + table_nm[i + 1] * f


@njit(cache=True, inline="always", error_model="numpy")
def _friction_effects(c, table_nm, time_s, lane):
    """Dry levels with Stribeck, position friction and the friction table added (when any is on)."""
    for s in range(lane.shape[1]):
        ratio = lane[SPEED_NOW, s] * c.stribeck_inverse_speed
        extra_dry = c.position_friction * abs(lane[POSITION_NOW, s])
        if c.table_variable == 1:
            extra_dry += _tabulated(c, table_nm, abs(lane[SPEED_NOW, s]))
        elif c.table_variable == 2:
            extra_dry += _tabulated(c, table_nm, lane[POSITION_NOW, s])
        elif c.table_variable == 3:
            extra_dry += _tabulated(c, table_nm, time_s)
        lane[DRY_DYNAMIC, s] = lane[LANE_FDJ, s] + extra_dry + c.stribeck_amplitude / (1.0 + ratio * ratio)
        lane[DRY_STATIC, s] = lane[LANE_FSJ, s] + extra_dry


@njit(cache=True, inline="always", error_model="numpy")
def _advance_lanes(c, load_delta, j, lane):
    """Advance every lane (simulation) of a group by one step h: the loop LLVM vectorizes."""
    n_lanes = lane.shape[1]
    # Effects are evaluated apart, and only when on: inside the main loop a call (sin) would keep
    # it scalar, and any extra operation would cost every simulation-step of the base model.
    if c.with_cogging:
        for s in range(n_lanes):
            lane[COGGING, s] = c.cogging_amplitude * np.sin(c.cogging_wavenumber * lane[ANGLE_NOW, s] + c.cogging_phase)
    for s in range(n_lanes):
        command = lane[COMMAND0, s] + lane[COMMAND_STEP, s] * j
        levels = (
            lane[LOAD_SLOW, s],
            lane[COGGING, s],
            lane[DRY_DYNAMIC, s],
            lane[DRY_STATIC, s],
            lane[LANE_K_AID, s],
            lane[LANE_K_OPP, s],
        )
        state = (lane[CURRENT_NOW, s], lane[SPEED_NOW, s], lane[ANGLE_NOW, s], lane[POSITION_NOW, s])
        current, speed, angle, position, loss = advance(c, load_delta, command, levels, state)
        lane[CURRENT_NOW, s] = current
        lane[SPEED_NOW, s] = speed
        lane[ANGLE_NOW, s] = angle
        lane[POSITION_NOW, s] = position
        lane[SUM_POSITION, s] += position
        lane[SUM_SPEED, s] += speed
        lane[SUM_CURRENT, s] += current
        lane[SUM_LOSS, s] += loss


@njit(cache=True, nogil=True, error_model="numpy")
def run_group(c, inputs, first, lanes, out):
    """Simulate sims [first, first + lanes) in lock-step and write their interval means into ``out``.

    Over log interval k (``interval_steps[k]`` steps of h, so logs of any rate are exact), each
    simulation's command runs linearly from ``knots_rad[row, k]`` to ``knots_rad[row, k + 1]`` and
    every recorded signal is the mean over the interval's steps:

        out[r, first + s, k] = (1 / m_k) Σ_{j < m_k} x_r(t_k + (j + 1)·h),  m_k = interval_steps[k].

    The load's slow part is constant over an interval: from the aircraft (advanced by exact ZOH
    on the interval's mean deflection) or, when ``load.slow_table_nm`` is not empty, from that
    table (a logged hinge moment). Releases the GIL: the caller runs groups on its own threads.

    Parameters
    ----------
    inputs : (table_nm, load, per_sim, knots_rad, interval_steps, initial), as below
    table_nm : (K,) the friction table's values (``c.table_variable`` says against what; 0: unused)
    per_sim : (4, N) FDJ, FSJ, 1 − η_A, 1/η_O − 1, N a multiple of ``lanes``
    knots_rad : (1, K + 1) one command for the batch, or (N, K + 1) one per simulation
    interval_steps : (K,) int64, steps of h in each log interval
    initial : (3, N) position [rad], motor speed [rad/s], current [A] at t = 0
    out : (6, N, K) written for columns [first, first + lanes)
    """
    table_nm, load, per_sim, knots_rad, interval_steps, initial = inputs
    n_samples = out.shape[2]
    per_sim_command = knots_rad.shape[0] > 1
    use_table = load.slow_table_nm.shape[0] > 0
    load_delta = load.hinge_delta_nm * c.inverse_gear  # d(T_ext)/dθ_u [N·m/rad]
    lane = _start_lanes(c, load, per_sim, initial, first, lanes)
    aircraft = np.zeros((lanes, 4))  # Δx: every simulation starts at trim
    elapsed_steps = 0
    for k in range(n_samples):
        steps = interval_steps[k]
        for s in range(lanes):
            row = first + s if per_sim_command else 0
            lane[COMMAND0, s] = knots_rad[row, k]
            lane[COMMAND_STEP, s] = (knots_rad[row, k + 1] - knots_rad[row, k]) / steps
        lane[SUM_POSITION:] = 0.0
        if c.with_friction_effects:  # a loop of its own: its body in the base loop slowed that one 1.6x
            for j in range(steps):
                _friction_effects(c, table_nm, (elapsed_steps + j) * c.step_s, lane)
                _advance_lanes(c, load_delta, j, lane)
        else:
            for j in range(steps):
                _advance_lanes(c, load_delta, j, lane)
        elapsed_steps += steps
        _record(c, load, lane, (first, k), steps, out)
        for s in range(lanes):
            if use_table:
                lane[LOAD_SLOW, s] = load.slow_table_nm[min(k + 1, n_samples - 1)] * c.inverse_gear
            else:
                _advance_aircraft(load, aircraft[s], out[POSITION, first + s, k])
                lane[LOAD_SLOW, s] = _hinge_slow(load, aircraft[s], elapsed_steps * c.step_s) * c.inverse_gear


@njit(cache=True, inline="always", error_model="numpy")
def _start_lanes(c, load, per_sim, initial, first, lanes):
    """(N_LANE_ROWS, lanes): the group's state at t = 0, its health, and the load at trim."""
    lane = np.zeros((N_LANE_ROWS, lanes))
    group = slice(first, first + lanes)
    lane[CURRENT_NOW] = initial[INIT_CURRENT, group]
    lane[SPEED_NOW] = initial[INIT_SPEED, group]
    lane[POSITION_NOW] = initial[INIT_POSITION, group]
    lane[ANGLE_NOW] = initial[INIT_POSITION, group]  # the shaft starts centred in the dead band
    lane[LANE_FDJ] = per_sim[FDJ, group]
    lane[LANE_FSJ] = per_sim[FSJ, group]
    lane[LANE_K_AID] = per_sim[K_AID, group]
    lane[LANE_K_OPP] = per_sim[K_OPP, group]
    lane[DRY_DYNAMIC] = per_sim[FDJ, group]  # friction effects, when on, add to these every step
    lane[DRY_STATIC] = per_sim[FSJ, group]
    trim = np.zeros(4)
    for s in range(lanes):
        slow = load.slow_table_nm[0] if load.slow_table_nm.shape[0] > 0 else _hinge_slow(load, trim, 0.0)
        lane[LOAD_SLOW, s] = slow * c.inverse_gear
    return lane


@njit(cache=True, inline="always", error_model="numpy")
def _record(c, load, lane, at, steps, out):
    """Interval means of lane sums into ``out`` at ``at`` = (the group's first simulation, the interval k)."""
    first, k = at
    for s in range(lane.shape[1]):
        mean_position = lane[SUM_POSITION, s] / steps
        out[POSITION, first + s, k] = mean_position
        out[SPEED, first + s, k] = lane[SUM_SPEED, s] / steps
        out[CURRENT, first + s, k] = c.current_sensor_gain * lane[SUM_CURRENT, s] / steps + c.current_sensor_offset
        out[LOSS, first + s, k] = lane[SUM_LOSS, s] / steps
        # H_e is affine in θ_u within an interval, so its mean follows from the mean position.
        hinge = lane[LOAD_SLOW, s] * c.gear + load.hinge_delta_nm * mean_position
        out[HINGE, first + s, k] = hinge + c.hinge_sensor_bias
        out[COMMAND, first + s, k] = lane[COMMAND0, s] + lane[COMMAND_STEP, s] * (steps - 1) / 2
