"""An independent servo: the controller's law as its documents define it, the load solved exactly between two of
its samples, and its own set points (smooth moves between random stations, not the EMPS's bang-bang).

Between controller samples the force is constant and, while the load slides one way, so is the friction's
Coulomb level, so the speed is an exponential, v(t) = F'/C + (v₀ − F'/C)·e^(−C·t/M), solved in closed form
(ema's simulator takes ten semi-implicit steps instead); a speed that would cross zero stops there, and a
load at rest stays there while the net force is within FDJ. A force once per turn of the motor (``Load.turn_n``)
is held over each 100th of a sample, solved the same way. ``draw`` returns an ``ema-window/1`` document and
the truth, never one of ema's objects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

RATE_HZ = 1000.0
KP, KV, GAIN, LIMIT = 160.0, 240.0, 35.0, 10.0  # an EMPS-like loop: 1/s, V/(m/s), N/V, V
STEP_M = 5e-8  # the encoder's step


@dataclass(frozen=True)
class Load:
    mass_kg: float = 90.0
    fdj_n: float = 20.0
    viscous_up_ns_per_m: float = 200.0
    viscous_down_ns_per_m: float = 200.0
    offset_n: float = -3.0
    turn_n: tuple[float, float] = (0.0, 0.0)  # a force once per turn of the motor, A·sin + B·cos of 2π·x/period
    travel_per_turn_m: float = 2.5e-3  # its period


def _turn_force(x: float, load: Load) -> float:
    angle = 2 * math.pi * x / load.travel_per_turn_m
    return load.turn_n[0] * math.sin(angle) + load.turn_n[1] * math.cos(angle)


TURN_PIECES = 100  # a force once per turn is held over this share of a sample (the load then travels < 1/200 turn)


def set_point(seed: int, seconds: float = 12.0) -> np.ndarray:
    """Moves between random stations in [0, 0.25] m, each a raised cosine of 0.4–1.5 s, with rests between."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(seconds * RATE_HZ)) / RATE_HZ
    out, now, at = np.zeros(len(t)), 0.0, 0.3
    while at < seconds:
        target, move, rest = rng.uniform(0.0, 0.25), rng.uniform(0.4, 1.5), rng.uniform(0.05, 0.5)
        inside = (t >= at) & (t < at + move)
        out[inside] = now + (target - now) * 0.5 * (1 - np.cos(np.pi * (t[inside] - at) / move))
        out[t >= at + move] = target
        now, at = target, at + move + rest
    return out


def _slide(v: float, force: float, load: Load, dt: float) -> tuple[float, float, float]:
    """(travel, speed, time) of a slide that keeps the sign of ``v`` for ``dt``, or stops at 0 within it."""
    direction = 1.0 if v > 0 else -1.0
    c = load.viscous_up_ns_per_m if direction > 0 else load.viscous_down_ns_per_m
    f = force - load.fdj_n * direction
    tau = load.mass_kg / c
    terminal = f / c
    stop = math.inf
    if terminal * direction < 0:  # heading for a stop
        stop = tau * math.log((v - terminal) / (0.0 - terminal))
    span = min(dt, stop)
    speed = terminal + (v - terminal) * math.exp(-span / tau)
    travel = terminal * span + (v - terminal) * tau * (1 - math.exp(-span / tau))
    return travel, (0.0 if span < dt else speed), span


def pulses(seed: int, n: int, height_n: float = 80.0, count: int = 6) -> np.ndarray:
    """A force pushing on the load in ``count`` pulses of 20–60 ms, either way, at random times [N]."""
    rng = np.random.default_rng(seed + 100)
    out = np.zeros(n)
    for start in rng.integers(n // 10, n - n // 10, size=count):
        out[start : start + int(rng.integers(20, 60))] = height_n * rng.choice([-1.0, 1.0])
    return out


def excitation(seed: int, n: int, height_v: float = 2.0, count: int = 8) -> np.ndarray:
    """A command added to the controller's for identification [V]: ``count`` pulses of 10–40 ms either way, at
    random times, and a slow sine of a tenth of their height (not the EMPS's own: its pulses are not published)."""
    rng = np.random.default_rng(seed + 200)
    out = 0.1 * height_v * np.sin(2 * np.pi * rng.uniform(0.2, 1.0) * np.arange(n) / RATE_HZ)
    for start in rng.integers(n // 10, n - n // 10, size=count):
        out[start : start + int(rng.integers(10, 40))] += height_v * rng.choice([-1.0, 1.0])
    return out


def simulate(
    reference: np.ndarray,
    load: Load,
    phase: float = 0.0,
    push_n: np.ndarray | None = None,
    added_v: np.ndarray | None = None,
    gains: tuple[float, float, float] = (KP, KV, GAIN),
) -> tuple[np.ndarray, np.ndarray]:
    """(position as the encoder read it [m], the drive's force [N]) at each controller sample; ``push_n`` a force
    on the load the log does not carry, ``added_v`` a command added to the controller's before its limit, ``gains``
    the loop's kp [1/s], kv [V/(m/s)] and drive gain [N/V]."""
    kp, kv, gain = gains
    dt = 1.0 / RATE_HZ
    x, v = float(reference[0]), 0.0
    previous = [x, x]
    positions, forces = np.empty(len(reference)), np.empty(len(reference))
    for k, r in enumerate(reference):
        q = STEP_M * round(x / STEP_M + phase) - phase * STEP_M
        filtered, filtered_before = 0.5 * (q + previous[0]), 0.5 * (previous[0] + previous[1])
        added = 0.0 if added_v is None else added_v[k]
        u = min(max(kv * (kp * (r - q) - (filtered - filtered_before) / dt) + added, -LIMIT), LIMIT)
        previous = [q, previous[0]]
        positions[k], forces[k] = q, gain * u
        net = gain * u - load.offset_n + (0.0 if push_n is None else push_n[k])
        if load.turn_n == (0.0, 0.0):
            x, v = _sample(x, v, net, load, dt)
            continue
        for _ in range(TURN_PIECES):
            x, v = _sample(x, v, net - _turn_force(x, load), load, dt / TURN_PIECES)
    return positions, forces


def _sample(x: float, v: float, net: float, load: Load, dt: float) -> tuple[float, float]:
    """(position, speed) after ``dt`` under the net force ``net``, solved in closed form (module docstring)."""
    left = dt
    while left > 1e-12 * dt * RATE_HZ:
        if v == 0.0:
            if abs(net) <= load.fdj_n:
                break  # stuck for the rest of it
            v = math.copysign(1e-15, net)  # breaks away the way the net force pushes
        travel, v, used = _slide(v, net, load, left)
        x += travel
        left -= used
    return x, v


def draw(seed: int, load: Load = Load(), seconds: float = 12.0, pushed: bool = False, excited: bool = False) -> dict:
    """An ``ema-window/1`` document of a servo with ``load``, its controller's constants in it; ``pushed``: with
    force pulses on the load that the log does not carry; ``excited``: with a command added to the controller's
    (``excitation``), which the logged force carries."""
    reference = set_point(seed, seconds)
    push = pulses(seed, len(reference)) if pushed else None
    added = excitation(seed, len(reference)) if excited else None
    phase = float(np.random.default_rng(seed + 1).uniform())
    position, force = simulate(reference, load, phase=phase, push_n=push, added_v=added)
    return {
        "schema": "ema-window/1",
        "actuator_id": "foreign/servo",
        "window_id": f"servo-{seed}",
        "sample_rate_hz": RATE_HZ,
        "signals": {
            "set_point_m": reference.tolist(),
            "position_m": position.tolist(),
            "drive_force_n": force.tolist(),
        },
        "constants": {"position_gain_per_s": KP, "speed_gain_per_mps": KV, "drive_gain_n_per_unit": GAIN},
    }


DOCUMENT = {
    "schema": "ema-actuator/1",
    "name": "a foreign servo",
    "kind": "servo",
    "servo": {"command_limit": LIMIT, "speed_filter": [0.5, 0.5]},
}
