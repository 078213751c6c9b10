"""Command families of real flight windows, drawn independently of ``ema.kinds.rotary.simulator.commands`` (test-only).

Each family returns ``command(t)``, a vectorized function of time [s] (t may start before 0: a
window cut from a longer flight), and is what a pilot, an autopilot or the thesis would send.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Command = Callable[[np.ndarray], np.ndarray]
FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")


def thesis(rng: np.random.Generator, duration_s: float) -> Command:
    """§5.6 as written: 0° and five values in ±25° at six instants, the quintic through them, unclipped."""
    knots_t = np.linspace(0.0, duration_s, 6)
    knots_v = np.concatenate([[0.0], rng.uniform(-25.0, 25.0, 5)])
    coefficients = np.polyfit(knots_t, knots_v, 5)
    return lambda t: np.polyval(coefficients, np.clip(t, 0.0, None))


def cruise(rng: np.random.Generator, duration_s: float) -> Command:
    """Small autopilot corrections: two or three sines of 1–4° at 0.5–6 Hz around a trim offset."""
    count = rng.integers(2, 4)
    amplitude = rng.uniform(1.0, 4.0, count) / np.sqrt(count)
    frequency = rng.uniform(0.5, 6.0, count)
    phase = rng.uniform(0, 2 * np.pi, count)
    offset = rng.uniform(-3.0, 1.0)
    a, f, p = amplitude[:, None], frequency[:, None], phase[:, None]
    return lambda t: offset + np.sum(a * np.sin(2 * np.pi * f * t + p), axis=0)


def gust(rng: np.random.Generator, duration_s: float) -> Command:
    """Gust rejection: band-limited random motion of a few degrees (random Fourier series, 1–15 Hz)."""
    frequency = rng.uniform(1.0, 15.0, 12)
    weight = rng.normal(size=12) / frequency
    phase = rng.uniform(0, 2 * np.pi, 12)
    scale = rng.uniform(2.0, 6.0) / np.sqrt(np.sum(weight**2) / 2)
    return lambda t: scale * np.sum(weight[:, None] * np.sin(2 * np.pi * frequency[:, None] * t + phase[:, None]), 0)


def doublet(rng: np.random.Generator, duration_s: float) -> Command:
    """A pilot doublet: +A, then −A, then back, each a sharp step (A 3–8°)."""
    amplitude = rng.uniform(3.0, 8.0) * rng.choice([-1.0, 1.0])
    start = rng.uniform(0.05, 0.2) * duration_s
    half = rng.uniform(0.15, 0.3) * duration_s
    return lambda t: (
        amplitude * ((t >= start) & (t < start + half)) - amplitude * ((t >= start + half) & (t < start + 2 * half))
    )


def steps(rng: np.random.Generator, duration_s: float) -> Command:
    """Step-and-hold: a staircase of random levels in ±12°, held 40–200 ms each."""
    holds = rng.uniform(0.04, 0.2, 200)
    edges = np.cumsum(holds) - holds[0] * rng.uniform()
    levels = rng.uniform(-12.0, 12.0, 201)
    return lambda t: levels[np.searchsorted(edges, t)]


def sweep(rng: np.random.Generator, duration_s: float) -> Command:
    """A pre-flight or bench sweep: the surface driven from rest through a slow sine of 5–20° at 0.5–3 Hz,
    its amplitude ramped in over the first tenth of the window."""
    amplitude, frequency = rng.uniform(5.0, 20.0), rng.uniform(0.5, 3.0)
    offset = rng.uniform(-2.0, 2.0)
    ramp_in = 0.1 * duration_s
    return lambda t: np.clip(t / ramp_in, 0.0, 1.0) * (offset + amplitude * np.sin(2 * np.pi * frequency * t))


def hold(rng: np.random.Generator, duration_s: float) -> Command:
    """A held position: no motion at all (carries no friction information)."""
    level = rng.uniform(-5.0, 5.0)
    return lambda t: np.full_like(t, level)


def stops(rng: np.random.Generator, duration_s: float) -> Command:
    """Into the end stops and back: a command past ±30° (32–40°), one way then the other, each held a third or more of
    the window: the surface rests on its stop while the motor pushes (a pilot's full deflection)."""
    level, sign = rng.uniform(32.0, 40.0), rng.choice([-1.0, 1.0])
    hold = rng.uniform(0.3, 0.45) * duration_s
    first = rng.uniform(0.05, 0.15) * duration_s
    knots_t = [0.0, first, first + hold, first + hold + 0.05 * duration_s, duration_s]
    knots_v = [0.0, sign * level, sign * level, -sign * level, -sign * level]
    return lambda t: np.interp(t, knots_t, knots_v)


BY_NAME: dict[str, Callable[[np.random.Generator, float], Command]] = {
    "thesis": thesis,
    "cruise": cruise,
    "gust": gust,
    "doublet": doublet,
    "steps": steps,
    "hold": hold,
    "sweep": sweep,
    "stops": stops,
}
