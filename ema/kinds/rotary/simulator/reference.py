"""The same model written as plain NumPy, vectorized across simulations: the baseline the kernel is
measured against, and an independent check of its arithmetic (tests compare the two).

Slow by design of NumPy, not by neglect: every 1 µs step is some forty array operations, each a
pass over the batch, so it is only timed on short horizons.
"""

from __future__ import annotations

import numpy as np

from ema.kinds.rotary.simulator.kernels import KernelConstants
from ema.kinds.rotary.simulator.loads import LoadModel


def _hinge_slow(load: LoadModel, aircraft: np.ndarray, time_s: float) -> np.ndarray:
    alpha_t = np.clip(load.alpha_t0_rad + aircraft @ load.alpha_t_row, -load.alpha_t_limit_rad, load.alpha_t_limit_rad)
    return load.hinge_bias_nm + load.hinge_alpha_nm * alpha_t + load.hinge_ramp_nmps * time_s


Arrays = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _step(
    c: KernelConstants,
    state: Arrays,
    command: np.ndarray,
    load_slow: np.ndarray,
    load_delta: float,
    per_sim: np.ndarray,
) -> Arrays:
    """One step h for every simulation: controller, RL phase, Borello friction, end stops, backlash."""
    fdj, fsj, k_aid, k_opp = per_sim
    current, speed, angle, position, _ = state
    speed_ref = np.minimum(np.maximum(c.position_gain * (command - position), -c.max_speed_ref), c.max_speed_ref)
    current_ref = np.minimum(np.maximum(c.speed_gain_over_kt * (speed_ref - speed), -c.max_current), c.max_current)
    current_ref = current_ref - c.current_ref_shift
    voltage_step = np.where(
        current_ref > current, c.voltage_step, np.where(current_ref < current, -c.voltage_step, 0.0)
    )
    current = c.current_decay * current + voltage_step - c.back_emf_step * speed
    motor_torque = np.minimum(np.maximum(c.torque_constant * current, -c.max_torque), c.max_torque)
    load_torque = load_slow + load_delta * position
    viscous = c.viscous * speed
    drive = motor_torque + load_torque - viscous
    direction = np.sign(np.where(speed != 0.0, speed, drive))
    k_load = np.where(load_torque * direction > 0.0, k_aid, k_opp)
    load_part = k_load * np.abs(load_torque)
    stuck = (speed == 0.0) & (np.abs(drive) <= fsj + load_part)
    friction = np.where(stuck, drive, (fdj + load_part) * direction)
    new_speed = speed + c.step_over_inertia * (drive - friction)
    new_speed = np.where(new_speed * speed < 0.0, 0.0, new_speed)
    free_angle = angle + c.step_over_gear * new_speed
    angle = np.minimum(np.maximum(free_angle, -c.end_stop), c.end_stop)
    new_speed = np.where(np.abs(free_angle) > c.end_stop, 0.0, new_speed)
    position = np.minimum(np.maximum(position, angle - c.half_backlash), angle + c.half_backlash)
    return current, new_speed, angle, position, friction + viscous


def simulate_numpy(
    c: KernelConstants,
    load: LoadModel,
    per_sim: np.ndarray,
    knots_rad: np.ndarray,
    initial: np.ndarray,
    interval_steps: np.ndarray,
) -> np.ndarray:
    """(6, N, n_samples) interval means, rows as ``simulator.kernels`` (position, speed, current, hinge, command, loss).

    Base model only: the effects that act inside the step (cogging, Stribeck, position friction)
    are not modelled here; those folded into ``c`` (viscous, gains, sensor bias, backlash) are.
    """
    n_sims = per_sim.shape[1]
    # state: current, speed, angle, position, loss of the last step
    state = (initial[2].copy(), initial[1].copy(), initial[0].copy(), initial[0].copy(), np.zeros(n_sims))
    aircraft = np.zeros((n_sims, 4))
    load_delta = load.hinge_delta_nm * c.inverse_gear
    load_slow = _hinge_slow(load, aircraft, 0.0) * c.inverse_gear
    n_samples, elapsed = len(interval_steps), 0
    rows = np.arange(n_sims) if knots_rad.shape[0] > 1 else np.zeros(n_sims, dtype=int)
    out = np.empty((6, n_sims, n_samples))
    for k in range(n_samples):
        steps = int(interval_steps[k])
        command0 = knots_rad[rows, k]
        command_step = (knots_rad[rows, k + 1] - knots_rad[rows, k]) / steps
        sums = np.zeros((4, n_sims))
        for j in range(steps):
            state = _step(c, state, command0 + command_step * j, load_slow, load_delta, per_sim)
            sums += (state[3], state[1], state[0], state[4])
        mean_position = sums[0] / steps
        out[0, :, k], out[1, :, k] = mean_position, sums[1] / steps
        out[2, :, k] = c.current_sensor_gain * sums[2] / steps + c.current_sensor_offset
        out[5, :, k] = sums[3] / steps
        out[3, :, k] = load_slow * c.gear + load.hinge_delta_nm * mean_position + c.hinge_sensor_bias
        out[4, :, k] = command0 + command_step * (steps - 1) / 2
        aircraft = aircraft @ load.ad.T + np.outer(mean_position - load.trim_elevator_rad, load.bd)
        elapsed += steps
        load_slow = _hinge_slow(load, aircraft, elapsed * c.step_s) * c.inverse_gear
    return out
