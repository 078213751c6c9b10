"""An independent geared servo on a pendulum, and its recorder's JSON log, for tests only.

Written from the physics, not from ema's kernel: the firmware's P loop runs at its own rate (1 kHz, ten ticks per
logged sample), the motor's current follows its winding's time constant L/R (exactly, over a tick), the shaft is
stepped by semi-implicit Euler, and the
gear train's friction is Borello's with a Karnopp stick band. The recorder writes what a real one writes: time stamps
that jitter, the position in encoder counts, the applied duty as a present-load register in sign and magnitude, a
supply that glitches for a sample, and the torque switched off where asked.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

G = 9.81
COUNTS = 4096  # the encoder's counts a turn


@dataclass(frozen=True)
class Servo:
    torque_constant: float = 2.4  # N·m/A at the output
    resistance: float = 6.0  # Ω
    inductance: float = 2e-3  # H
    inertia: float = 0.025  # kg·m², the servo's own at the output
    error_gain: float = 0.2  # duty per rad per unit of kp
    duty_limit: float = 0.97
    fdj: float = 0.12  # N·m
    viscous: float = 0.02  # N·m·s/rad
    eta_o: float = 0.85
    eta_a: float = 0.9
    delay_s: float = 0.0  # the set point's transport to the loop


@dataclass(frozen=True)
class Load:
    mass: float
    arm: float
    kp: float


def set_point(kind: str, seconds: float, rate: float, seed: int) -> np.ndarray:
    """A set point of the recorder's shapes: steps, a sine of sines, a slow rise and fall."""
    t = np.arange(round(seconds * rate)) / rate
    rng = np.random.default_rng(seed)
    if kind == "steps":
        levels = rng.uniform(-1.2, 1.2, size=6)
        return levels[np.minimum((t / seconds * 6).astype(int), 5)]
    if kind == "sines":
        return 0.9 * np.sin(2 * np.pi * 0.4 * t) * np.sin(2 * np.pi * 0.13 * t + 0.5)
    return 1.3 * np.clip(np.sin(np.pi * t / seconds) * 1.4, -1, 1)


def simulate(servo: Servo, load: Load, reference: np.ndarray, on: np.ndarray, rate: float, supply: float):
    """(position, duty) at each logged sample, the loop run at 1 kHz in between (module docstring)."""
    ticks, dt = 10, 1.0 / rate / 10
    moment, inertia = G * load.mass * load.arm, servo.inertia + load.mass * load.arm**2
    q, v, current = 0.0, 0.0, 0.0
    lag = round(servo.delay_s * rate)
    positions, duties = [], []
    for k in range(len(reference)):
        positions.append(q)
        target = reference[max(k - lag, 0)]
        applied = []
        for _ in range(ticks):
            duty = float(np.clip(load.kp * servo.error_gain * (target - q), -servo.duty_limit, servo.duty_limit))
            applied.append(duty)
            volts = duty * supply if on[k] else servo.torque_constant * v  # off: no current flows
            settled = (volts - servo.torque_constant * v) / servo.resistance  # the winding's current, exactly over dt
            current = settled + (current - settled) * np.exp(-dt * servo.resistance / servo.inductance)
            tau_m = servo.torque_constant * current if on[k] else 0.0
            tau_g = -moment * np.sin(q)
            way = np.sign(v) if abs(v) > 1e-4 else np.sign(tau_m + tau_g)
            opposing = tau_g * way < 0
            friction = servo.fdj + (1 / servo.eta_o - 1 if opposing else 1 - servo.eta_a) * abs(tau_g)
            if abs(v) < 1e-4 and abs(tau_m + tau_g) <= friction:
                v = 0.0  # Karnopp: stuck while the drive is within the friction
                continue
            v += dt * (tau_m + tau_g - friction * way - servo.viscous * v) / inertia
            q += dt * v
        duties.append(float(np.mean(applied)))
    return np.array(positions), np.array(duties)


def recorder_log(
    path: Path,
    servo: Servo,
    load: Load,
    *,
    kind: str = "sines",
    seconds: float = 6.0,
    off_after_s: float | None = None,
    seed: int = 0,
) -> Path:
    """A run as the sysid recorder writes it: a header, then one entry a sample (module docstring)."""
    rate, supply = 100.0, 12.0
    reference = set_point(kind, seconds, rate, seed)
    on = np.ones(len(reference), dtype=bool) if off_after_s is None else np.arange(len(reference)) / rate < off_after_s
    position, duty = simulate(servo, load, reference, on, rate, supply)
    rng = np.random.default_rng(seed + 1)
    stamps = np.arange(len(reference)) / rate + rng.uniform(-0.002, 0.002, size=len(reference))
    stamps[0] = 0.0
    volts = np.full(len(reference), supply)
    volts[rng.integers(10, len(reference) - 10)] = 0.0  # the reading glitches for a sample
    step = 2 * np.pi / COUNTS
    entries = []
    for i in range(len(reference)):
        magnitude = round(abs(duty[i]) * 1000) if on[i] else 0
        register = (1024 + magnitude if duty[i] >= 0 else magnitude) / 100.0
        entries.append(
            {
                "timestamp": float(stamps[i]),
                "position": float(step * np.round(position[i] / step)),
                "goal_position": float(reference[i]),
                "torque": register,
                "input_volts": float(volts[i]),
                "torque_enable": bool(on[i]),
                "speed": 0.0,
                "load": 0,
            }
        )
    header = {"mass": load.mass, "length": load.arm, "kp": load.kp, "vin": 15.0, "trajectory": kind}
    path.write_text(json.dumps({**header, "entries": entries}))
    return path
