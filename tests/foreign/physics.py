"""The EMA of ``docs/model.md`` written again, independently of ``sim/``, for tests only.

Deliberate differences in form from ``ema.kinds.rotary.simulator.kernels`` (each one a legitimate reading of the spec):

- one scalar loop per window, branches and all, no lock-step lanes;
- the RL phase integrated exactly over each 1 µs step (exponential), not by explicit Euler;
- the shaft angle by the trapezoidal rule; end stops and the dead band as explicit branches;
- the aircraft integrated by RK4 every 100 µs from the instantaneous deflection, the hinge
  moment evaluated at every step, trim interpolated at the *true* airspeed;
- the command held in a 100 kHz table, linearly interpolated;
- log intervals of any length (a 3 kHz log has 333 or 334 steps per interval);
- effects in forms the rotary simulator's ``effects`` has not: a Gaussian friction bump over elevator position,
  a tanh Stribeck curve, dynamic friction drifting in time, cogging as a cosine of any order;
- a loop that may depart from the spec's, unlogged: bus voltage, position gain, a lag between the
  logged command and the one the loop follows, a noisy speed reading;
- any actuator of the architecture (``Drive``: gear ratio, motor, inertia, gains, backlash, stops),
  and on the ground (``Ground``) a load cell's prescribed load, constant or ramped, in place of the
  aircraft.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

STEP_S = 1e-6
COMMAND_TABLE_HZ = 100_000.0
AIRCRAFT_EVERY = 100  # steps between RK4 steps of the aircraft
LOOP_SAMPLE_STEPS = 100  # the loop's sensors are read at 10 kHz
# Indices of the parameter vector the loop reads.
(
    P_GP,
    P_GAP,
    P_R,
    P_L,
    P_KT,
    P_KE,
    P_TMAX,
    P_VMAX,
    P_IMAX,
    P_J,
    P_C,
    P_BLK,
    P_STOP,
    P_FSJ,
    P_FDJ,
    P_ASYM,
    P_KAID,
    P_KOPP,
    P_ISENSE,
    P_IBIAS,
    P_HBIAS,
    P_BUMP_A,
    P_BUMP_C,
    P_BUMP_W,
    P_STRIB_A,
    P_STRIB_W,
    P_DRIFT,
    P_COG_A,
    P_COG_P,
    P_COG_PHI,
    P_QSC,
    P_CHA,
    P_CHD,
    P_DWN,
    P_LT,
    P_V,
    P_ALPHA_TRIM,
    P_DELTA_TRIM,
    P_ALPHA_LIM,
    P_VBUS,
    P_GEAR,
    P_KT_LOOP,
    P_GROUND,
    P_LOAD0,
    P_LOAD_RAMP,
    N_P,
) = range(46)


@dataclass(frozen=True)
class Drive:
    """An actuator of the spec's architecture: its constants (the thesis's Table 3.1 by default)."""

    position_gain_per_s: float = 1e5
    speed_gain_nms: float = 5e-2
    resistance_ohm: float = 2.13
    inductance_h: float = 7.2e-4
    torque_constant_nm_per_a: float = 0.0752
    max_motor_torque_nm: float = 1.689
    supply_voltage_v: float = 48.0
    max_current_a: float = 22.5
    gear_ratio: float = 500.0
    inertia_kgm2: float = 2.5e-5
    viscous_nms: float = 5.172e-5
    backlash_rad: float = 5e-3
    end_stop_deg: float = 30.0


THESIS = Drive()


@dataclass(frozen=True)
class Health:
    fdj_nm: float = 0.05
    fsj_nm: float = 0.10
    eta_o: float = 0.85

    def eta_a(self, gear: float = THESIS.gear_ratio) -> float:
        n = gear
        return (2 * n * n * self.eta_o - n * n + n) / (n * n * self.eta_o + n - self.eta_o + 1)


@dataclass(frozen=True)
class Effects:
    """Departures from the base model, each neutral by default (test-only forms)."""

    viscous_factor: float = 1.0  # total C = factor · C_M
    torque_constant_gain: float = 1.0  # true k_T = k_e over nominal
    inertia_factor: float = 1.0  # true J_M over the spec's (a rotor, screw and gears reflected otherwise than it says)
    current_sensor_gain: float = 1.0  # logged (and fed back) current over true current
    current_bias_a: float = 0.0  # logged (and fed back) current minus current_sensor_gain × true
    hinge_bias_nm: float = 0.0  # logged hinge moment minus true
    fdj_asymmetry: float = 0.0  # dynamic friction FDJ·(1 + a) turning one way, FDJ·(1 − a) the other
    bump_nm: float = 0.0  # Gaussian friction bump (spall): height [N·m] on FDJ and FSJ
    bump_centre_deg: float = 0.0
    bump_width_deg: float = 1.0  # standard deviation of the bump [deg]
    backlash_factor: float = 1.0  # total dead band = factor · BLK
    stribeck_nm: float = 0.0  # extra dynamic friction at rest, decaying as 1 − tanh(|ω|/ω_s)
    stribeck_speed_radps: float = 100.0
    drift_per_s: float = 0.0  # FDJ(t) = FDJ · (1 + drift · t), t from the window's start
    cogging_nm: float = 0.0  # A · cos(p · θ_m + φ)
    cogging_periods: float = 12.0  # per motor revolution
    cogging_phase_rad: float = 0.0
    # A controller that departs slightly from the spec's loop (the log does not show it):
    position_gain_factor: float = 1.0  # true G_P over the spec's
    supply_voltage_factor: float = 1.0  # the bus voltage the PWM switches over the spec's V_max (not ω_max)
    loop_delay_s: float = 0.0  # the loop acts on the command this much later than it is logged
    loop_noise_radps: float = 0.0  # std of the noise on the speed the loop reads (new every LOOP_SAMPLE_STEPS)
    loop_noise_seed: int = 0


@dataclass(frozen=True)
class Flight:
    airspeed_mps: float = 153.01
    altitude_m: float = 0.0


@dataclass(frozen=True)
class Ground:
    """On the ground: a load cell's prescribed hinge moment, H = load_nm + ramp_nmps · t (t from the window's
    start), in place of the aircraft; zero for a pre-flight sweep."""

    load_nm: float = 0.0
    ramp_nmps: float = 0.0


@dataclass(frozen=True)
class Setup:
    health: Health = field(default_factory=Health)
    effects: Effects = field(default_factory=Effects)
    flight: Flight | Ground = field(default_factory=Flight)
    sample_rate_hz: float = 10_000.0
    drive: Drive = THESIS


def _density(altitude_m: float) -> float:
    return 1.225 * (1.0 - 2.2558e-5 * altitude_m) ** 4.2559


def aircraft_matrices(flight: Flight) -> tuple[np.ndarray, np.ndarray]:
    """A and B of the aircraft (``docs/model.md``), scaled to the flight condition as it prescribes."""
    a = np.array(
        [
            [-1.9311e-2, 2.68703, -9.80542, -0.175257],
            [-8.3297e-4, -1.0189, 0.0, 0.90506],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.82225, 0.0, -1.0774],
        ]
    )
    b = np.array([3.03345, -0.123180, 0.0, -10.0583])
    v0 = 502 * 0.3048
    k_rho = _density(flight.altitude_m) / 1.225
    k_v, k_q = k_rho * flight.airspeed_mps / v0, k_rho * (flight.airspeed_mps / v0) ** 2
    a[3, 1] *= k_q
    b[3] *= k_q
    a[1, 1] *= k_v
    a[3, 3] *= k_v
    b[1] *= k_v
    a[1, 0] = -2 * 9.80665 / flight.airspeed_mps**2
    a[1, 3] = 1 - (1 - 0.90506) * k_rho
    return a, b


def trim_rad(flight: Flight) -> tuple[float, float]:
    """Trim α and δe interpolated in the spec's table at the true airspeed."""
    table = np.array(
        [[300, 8.49, -0.591], [400, 4.16, -0.591], [500, 2.14, -0.756], [600, 1.04, -0.846], [700, 0.382, -0.900]]
    )
    v_ftps = flight.airspeed_mps / 0.3048
    return (
        np.radians(np.interp(v_ftps, table[:, 0], table[:, 1])),
        np.radians(np.interp(v_ftps, table[:, 0], table[:, 2])),
    )


def parameters(setup: Setup) -> np.ndarray:
    h, e, f, d = setup.health, setup.effects, setup.flight, setup.drive
    p = np.zeros(N_P)
    p[P_GP], p[P_GAP] = d.position_gain_per_s * e.position_gain_factor, d.speed_gain_nms
    p[P_R], p[P_L] = d.resistance_ohm, d.inductance_h
    p[P_KT] = p[P_KE] = d.torque_constant_nm_per_a * e.torque_constant_gain
    p[P_KT_LOOP], p[P_GEAR] = d.torque_constant_nm_per_a, d.gear_ratio
    p[P_TMAX], p[P_VMAX], p[P_IMAX] = d.max_motor_torque_nm, d.supply_voltage_v, d.max_current_a
    p[P_J], p[P_C] = d.inertia_kgm2 * e.inertia_factor, d.viscous_nms * e.viscous_factor
    p[P_BLK], p[P_STOP] = d.backlash_rad * e.backlash_factor, np.radians(d.end_stop_deg)
    p[P_FSJ], p[P_FDJ], p[P_ASYM] = h.fsj_nm, h.fdj_nm, e.fdj_asymmetry
    p[P_KAID], p[P_KOPP] = 1.0 - h.eta_a(d.gear_ratio), 1.0 / h.eta_o - 1.0
    p[P_ISENSE], p[P_IBIAS], p[P_HBIAS] = e.current_sensor_gain, e.current_bias_a, e.hinge_bias_nm
    p[P_BUMP_A], p[P_BUMP_C], p[P_BUMP_W] = e.bump_nm, np.radians(e.bump_centre_deg), np.radians(e.bump_width_deg)
    p[P_STRIB_A], p[P_STRIB_W], p[P_DRIFT] = e.stribeck_nm, e.stribeck_speed_radps, e.drift_per_s
    p[P_COG_A], p[P_COG_P], p[P_COG_PHI] = e.cogging_nm, e.cogging_periods, e.cogging_phase_rad
    p[P_ALPHA_LIM] = np.radians(15.0)
    p[P_VBUS] = d.supply_voltage_v * e.supply_voltage_factor
    if isinstance(f, Ground):
        p[P_GROUND], p[P_LOAD0], p[P_LOAD_RAMP], p[P_V] = 1.0, f.load_nm, f.ramp_nmps, 1.0
        return p
    p[P_QSC] = 0.5 * _density(f.altitude_m) * f.airspeed_mps**2 * 0.34 * 0.25
    p[P_CHA], p[P_CHD], p[P_DWN], p[P_LT], p[P_V] = -0.25, -0.55, 0.4, 4.6, f.airspeed_mps
    p[P_ALPHA_TRIM], p[P_DELTA_TRIM] = trim_rad(f)
    return p


@njit(cache=True)
def _derivative(a, b, x, u):
    return a @ x + b * u


@njit(cache=True)
def _hinge(p, x, theta_u, t):
    if p[P_GROUND] > 0.0:
        return p[P_LOAD0] + p[P_LOAD_RAMP] * max(t, 0.0)
    alpha = p[P_ALPHA_TRIM] + x[1]
    alpha_t = (1.0 - p[P_DWN]) * alpha + p[P_LT] * x[3] / p[P_V]
    alpha_t = max(-p[P_ALPHA_LIM], min(p[P_ALPHA_LIM], alpha_t))
    return p[P_QSC] * (p[P_CHA] * alpha_t + p[P_CHD] * theta_u)


@njit(cache=True)
def _current(p, command, theta_u, speed, current, decay):
    """The current after one step: the speed and current loops bang the supply on the *measured* current."""
    measured_current = p[P_ISENSE] * current + p[P_IBIAS]
    top = p[P_VMAX] / p[P_KT_LOOP]
    speed_ref = max(-top, min(top, p[P_GP] * (command - theta_u)))
    current_ref = max(-p[P_IMAX], min(p[P_IMAX], p[P_GAP] * (speed_ref - speed) / p[P_KT_LOOP]))
    voltage = 0.0
    if current_ref > measured_current:
        voltage = p[P_VBUS]
    elif current_ref < measured_current:
        voltage = -p[P_VBUS]
    steady = (voltage - p[P_KE] * speed) / p[P_R]
    return steady + (current - steady) * decay


@njit(cache=True)
def _new_speed(p, t, h, angles, motion, load):
    """Motor speed after one explicit Euler step, with stick-slip; ``angles`` = (θ_u, θ_m), ``motion`` =
    (speed, current)."""
    theta_u, theta_m = angles
    speed, current = motion
    torque = max(-p[P_TMAX], min(p[P_TMAX], p[P_KT] * current))
    bump = p[P_BUMP_A] * np.exp(-0.5 * ((theta_u - p[P_BUMP_C]) / p[P_BUMP_W]) ** 2)
    dynamic = p[P_FDJ] * (1.0 + p[P_DRIFT] * max(t, 0.0)) + bump
    dynamic += p[P_STRIB_A] * (1.0 - np.tanh(abs(speed) / p[P_STRIB_W]))
    static = p[P_FSJ] + bump + p[P_STRIB_A]
    cogging = p[P_COG_A] * np.cos(p[P_COG_P] * theta_m + p[P_COG_PHI])
    drive = torque + load - p[P_C] * speed + cogging
    sense = (1.0 if speed > 0 else -1.0) if speed != 0.0 else (1.0 if drive > 0 else -1.0)
    dynamic += p[P_FDJ] * p[P_ASYM] * sense
    k = p[P_KAID] if load * sense > 0 else p[P_KOPP]
    accelerating = drive - (dynamic + k * abs(load)) * sense
    if speed != 0.0:
        new_speed = speed + h / p[P_J] * accelerating
        return 0.0 if new_speed * speed < 0 else new_speed
    if abs(drive) <= max(static, dynamic) + k * abs(load):
        return 0.0
    return h / p[P_J] * accelerating


@njit(cache=True)
def _rk4(a, b, x, u, dt):
    k1 = _derivative(a, b, x, u)
    k2 = _derivative(a, b, x + 0.5 * dt * k1, u)
    k3 = _derivative(a, b, x + 0.5 * dt * k2, u)
    k4 = _derivative(a, b, x + dt * k3, u)
    return x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


@njit(cache=True)
def _run(p, aircraft, tables, clock, theta0, out):
    """Integrate from step ``first_step`` (negative: a pre-roll before the log starts) to ``n_steps``, logging
    at ``rate_hz`` (``clock``); the loop follows ``command_rad`` and reads the speed with ``loop_noise_radps``
    (one value per block of LOOP_SAMPLE_STEPS) added, the log records ``logged_rad`` (both 100 kHz tables:
    ``tables``) and the true states; ``aircraft`` = (A, B)."""
    a, b = aircraft
    command_rad, logged_rad, loop_noise_radps = tables
    first_step, n_steps, rate_hz = clock
    h = 1e-6
    gear = p[P_GEAR]
    current, speed = 0.0, 0.0
    theta_u = theta0
    theta_m = theta0 * gear
    x = np.zeros(4)
    decay = np.exp(-h * p[P_R] / p[P_L])
    sums = np.zeros(5)
    count = 0
    sample = 0
    for i in range(first_step, n_steps):
        pos = (i - first_step) * h * 1e5
        j = int(pos)
        command = command_rad[j] + (pos - j) * (command_rad[j + 1] - command_rad[j])
        logged = logged_rad[j] + (pos - j) * (logged_rad[j + 1] - logged_rad[j])
        block = (i - first_step) // LOOP_SAMPLE_STEPS
        current = _current(p, command, theta_u, speed + loop_noise_radps[block], current, decay)
        new_speed = _new_speed(p, i * h, h, (theta_u, theta_m), (speed, current), _hinge(p, x, theta_u, i * h) / gear)
        theta_m += 0.5 * h * (speed + new_speed)
        speed = new_speed
        limit = p[P_STOP] * gear
        if theta_m > limit:
            theta_m = limit
            speed = min(speed, 0.0)
        elif theta_m < -limit:
            theta_m = -limit
            speed = max(speed, 0.0)
        motor_side = theta_m / gear
        if motor_side - theta_u > 0.5 * p[P_BLK]:
            theta_u = motor_side - 0.5 * p[P_BLK]
        elif motor_side - theta_u < -0.5 * p[P_BLK]:
            theta_u = motor_side + 0.5 * p[P_BLK]
        if (i - first_step + 1) % AIRCRAFT_EVERY == 0:  # RK4 over 100 µs on the instantaneous deflection
            x = _rk4(a, b, x, theta_u - p[P_DELTA_TRIM], AIRCRAFT_EVERY * h)
        if i >= 0:
            sums[0] += theta_u
            sums[1] += speed
            sums[2] += p[P_ISENSE] * current + p[P_IBIAS]
            sums[3] += _hinge(p, x, theta_u, i * h) + p[P_HBIAS]
            sums[4] += logged
            count += 1
            if (i + 1) * h * rate_hz >= sample + 1 - 1e-9:
                for r in range(5):
                    out[r, sample] = sums[r] / count
                    sums[r] = 0.0
                count = 0
                sample += 1
                if sample == out.shape[1]:
                    return


def _loop_noise(effects: Effects, steps: int) -> np.ndarray:
    """(blocks,) noise on the speed [rad/s] the loop reads, one value per LOOP_SAMPLE_STEPS."""
    draws = np.random.default_rng(effects.loop_noise_seed).standard_normal(steps // LOOP_SAMPLE_STEPS + 1)
    return effects.loop_noise_radps * draws


def simulate(setup: Setup, command_deg, duration_s: float, preroll_s: float = 0.0) -> dict[str, np.ndarray]:
    """Clean logged signals of one window: ``command_deg(t)`` a vectorized function of time [s]
    (t from −preroll_s), the actuator at rest where the command starts, the aircraft at trim."""
    rate = setup.sample_rate_hz
    n_samples = int(np.floor(duration_s * rate + 1e-9))
    table_t = np.arange(-preroll_s, duration_s + 2e-5, 1.0 / COMMAND_TABLE_HZ)
    logged_rad = np.radians(np.asarray(command_deg(table_t), dtype=np.float64))
    command_rad = np.radians(np.asarray(command_deg(table_t - setup.effects.loop_delay_s), dtype=np.float64))
    a, b = (np.zeros((4, 4)), np.zeros(4)) if isinstance(setup.flight, Ground) else aircraft_matrices(setup.flight)
    out = np.zeros((5, n_samples))
    first, last = -round(preroll_s / STEP_S), round(duration_s / STEP_S) + 10
    stop = np.radians(setup.drive.end_stop_deg)
    start = float(np.clip(command_rad[0], -stop, stop))
    tables = (command_rad, logged_rad, _loop_noise(setup.effects, last - first))
    _run(parameters(setup), (a, b), tables, (first, last, rate), start, out)
    names = ("position_deg", "motor_speed_radps", "current_a", "hinge_moment_nm", "command_deg")
    signals = dict(zip(names, out, strict=True))
    signals["position_deg"] = np.degrees(signals["position_deg"])
    signals["command_deg"] = np.degrees(signals["command_deg"])
    return signals
