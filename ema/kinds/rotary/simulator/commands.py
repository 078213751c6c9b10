"""Elevator commands: the thesis §5.6 random command and the knots the kernel interpolates.

The kernel takes a command as *knots*: its values at the boundaries of the log intervals
(n_samples + 1 of them), interpolated linearly at every 1 µs step. A synthetic command is
evaluated there exactly; a logged command (interval means) is turned into knots by
:func:`knots_from_samples`.
"""

from __future__ import annotations

import numpy as np

from ema.model.bounds import COMMAND_FAMILIES
from ema.model.checks import InputError, finite_array

COMMAND_AMPLITUDE_DEG = 25.0
COMMAND_POINTS = 5
# A 5th-order polynomial through ±25° points overshoots: about one command in three leaves ±28°
# between its nodes, one in ten ±42°. A flight-control computer never commands past the travel,
# so such draws are rejected (and redrawn) rather than driven into the 30° end stops.
COMMAND_LIMIT_DEG = 28.0
MAX_DRAWS = 1000  # two draws in three pass: a thousand misses in a row mean a span no command can be drawn over


def random_command_coefficients(duration_s: float, rng: np.random.Generator) -> np.ndarray:
    """Power-series coefficients (highest first, t in s) of one §5.6 command.

    Five values uniform in ±25° placed with a leading 0° at 6 equally spaced instants over
    [0, duration]; the 5th-order polynomial through the 6 points is unique.
    """
    times = np.linspace(0.0, duration_s, COMMAND_POINTS + 1)
    values = np.concatenate([[0.0], rng.uniform(-COMMAND_AMPLITUDE_DEG, COMMAND_AMPLITUDE_DEG, COMMAND_POINTS)])
    # Solving the Vandermonde system in normalized time keeps it well conditioned.
    coefficients_unit = np.linalg.solve(np.vander(times / duration_s), values)
    return coefficients_unit / duration_s ** np.arange(COMMAND_POINTS, -1, -1)


def random_command_knots(
    n_samples: int, sample_rate_hz: float, rng: np.random.Generator, n_commands: int = 1
) -> np.ndarray:
    """(n_commands, n_samples + 1) knots [deg] of independent §5.6 commands (Case 2 uses one per simulation);
    an InputError, never an endless redraw, where ``MAX_DRAWS`` draws per command all overshoot (no time span)."""
    duration_s = n_samples / sample_rate_hz
    times = np.arange(n_samples + 1) / sample_rate_hz
    dense = np.linspace(0.0, duration_s, 2001)  # fine enough to see any overshoot between knots
    commands: list[np.ndarray] = []
    for _ in range(MAX_DRAWS * n_commands + 1):
        if len(commands) == n_commands:
            return np.stack(commands)
        coefficients = random_command_coefficients(duration_s, rng)
        if np.max(np.abs(np.polyval(coefficients, dense))) <= COMMAND_LIMIT_DEG:
            commands.append(np.polyval(coefficients, times))
    raise InputError(
        "n_samples",
        f"no command over {duration_s:g} s stayed within ±{COMMAND_LIMIT_DEG:g}° in {MAX_DRAWS} draws a command",
    )


def _sines(times: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Autopilot corrections: two sines of 1–4° at 0.3–3 Hz around an offset of up to ±2°."""
    amplitude, frequency = rng.uniform(1.0, 4.0, 2) / np.sqrt(2), rng.uniform(0.3, 3.0, 2)
    phase = rng.uniform(0.0, 2 * np.pi, 2)
    return rng.uniform(-2.0, 2.0) + np.sin(2 * np.pi * np.outer(times, frequency) + phase) @ amplitude


def _gust(times: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Gust rejection: white noise through a 50 ms first-order lag, scaled to 2–5° RMS."""
    step = times[1] - times[0]
    noise = rng.normal(size=len(times))
    smooth = np.empty_like(noise)
    decay, level = np.exp(-step / 0.05), 0.0
    for i, value in enumerate(noise):
        level = decay * level + (1 - decay) * value
        smooth[i] = level
    return rng.uniform(2.0, 5.0) * smooth / max(float(np.std(smooth)), 1e-12)


def _doublet(times: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A pilot's doublet: +A for a fifth of the window, −A for the next fifth (A 2–8°), then back to 0."""
    duration = times[-1]
    start, half = rng.uniform(0.1, 0.3) * duration, 0.2 * duration
    amplitude = rng.uniform(2.0, 8.0) * rng.choice([-1.0, 1.0])
    return amplitude * ((times >= start) & (times < start + half)) - amplitude * (
        (times >= start + half) & (times < start + 2 * half)
    )


def _steps(times: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Step and hold: levels uniform in ±10°, each held 50–250 ms."""
    edges = np.cumsum(rng.uniform(0.05, 0.25, size=int(times[-1] / 0.05) + 2))
    levels = rng.uniform(-10.0, 10.0, size=len(edges) + 1)
    return levels[np.searchsorted(edges, times)]


def family_knots(family: str, n_samples: int, sample_rate_hz: float, rng: np.random.Generator) -> np.ndarray:
    """(n_samples + 1,) knots [deg] of one command of a family: the §5.6 polynomial, or what real
    flights mostly hold (cruise corrections, gust rejection, a pilot's doublet, steps and holds)."""
    if family == "thesis":
        return random_command_knots(n_samples, sample_rate_hz, rng)[0]
    makers = {"cruise": _sines, "gust": _gust, "doublet": _doublet, "steps": _steps}
    if family not in makers:
        raise InputError("command", f"unknown command family {family!r}; known: {', '.join(COMMAND_FAMILIES)}")
    return makers[family](np.arange(n_samples + 1) / sample_rate_hz, rng)


def knots_from_samples(command_deg: np.ndarray) -> np.ndarray:
    """Knots at interval boundaries from interval-mean samples.

    Inside, the fourth-order boundary value of cell means, (7·(c₋₁ + c₀) − (c₋₂ + c₁)) / 12, so a
    smooth command's means are reproduced to O(Δt⁴); the two knots at each end use the one-sided
    third-order formulas from the three nearest means. Each inner knot is then held between its
    two neighbouring means (the monotonicity limiter of PPM, Colella & Woodward 1984): a pilot's
    step would otherwise ring, 1/12 of the step past it on either side. At a smooth extremum the
    limiter costs at most |f''|·Δt²/6.
    Accepts (n_samples,) or (n_commands, n_samples); returns one more column.
    """
    samples = np.atleast_2d(finite_array("command_deg", command_deg))
    if samples.shape[-1] < 4:
        raise InputError("command_deg", "needs at least 4 samples")
    knots = np.empty((samples.shape[0], samples.shape[1] + 1))
    knots[:, 2:-2] = (7 * (samples[:, 1:-2] + samples[:, 2:-1]) - (samples[:, :-3] + samples[:, 3:])) / 12
    first, last = samples[:, :3], samples[:, :-4:-1]  # the three means nearest each end, outward first
    for edge, near in ((0, first), (-1, last)):
        knots[:, edge] = (11 * near[:, 0] - 7 * near[:, 1] + 2 * near[:, 2]) / 6
        knots[:, 1 if edge == 0 else -2] = (2 * near[:, 0] + 5 * near[:, 1] - near[:, 2]) / 6
    left, right = samples[:, :-1], samples[:, 1:]
    knots[:, 1:-1] = np.clip(knots[:, 1:-1], np.minimum(left, right), np.maximum(left, right))
    return knots
