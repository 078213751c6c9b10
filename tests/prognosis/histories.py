"""Wear histories drawn with laws only the tests implement (none of them is a law of ``ema.prognosis.laws``), with
the truth of when each crosses its threshold: FDJ rising from 0.05 N·m to the thesis's 0.075."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

START, THRESHOLD = 0.05, 0.075
RISE = THRESHOLD - START


def _doubling(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    """2^(t/T) − 1, scaled to reach the threshold at ``crossing`` (T an eighth of it: wear that feeds itself)."""
    period = crossing / 8.0
    return lambda t: START + RISE * (2.0 ** (t / period) - 1.0) / (2.0**8 - 1.0)


def _cube_plus(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    """A slow line plus the cube of the hours."""
    return lambda t: START + RISE * (0.1 * t / crossing + 0.9 * (t / crossing) ** 3)


def _onset(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    """Steady, then a rise that sets in smoothly (a softplus knee at 60 % of the crossing time)."""
    knee, width = 0.4 * crossing, 0.05 * crossing
    rise = lambda t: width * np.logaddexp(0.0, (t - knee) / width)  # noqa: E731
    return lambda t: START + RISE * rise(t) / rise(np.array(crossing))


def _blow_up(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    """A crack's growth: (1 − t/T)^−1 (Paris's law), reaching the threshold at ``crossing``."""
    end = crossing * 1.25
    scale = RISE / (1.0 / (1.0 - crossing / end) - 1.0)
    return lambda t: START + scale * (1.0 / (1.0 - np.minimum(t, 0.999 * end) / end) - 1.0)


def _sinh(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    return lambda t: START + RISE * np.sinh(4.0 * t / crossing) / np.sinh(4.0)


def _line(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    return lambda t: START + RISE * t / crossing


def _steady(crossing: float) -> Callable[[np.ndarray], np.ndarray]:
    return lambda t: np.full_like(np.asarray(t, dtype=float), START + 0.2 * RISE)


LAWS: dict[str, Callable[[float], Callable[[np.ndarray], np.ndarray]]] = {
    "line": _line,
    "doubling": _doubling,
    "cube": _cube_plus,
    "onset": _onset,
    "crack": _blow_up,
    "sinh": _sinh,
    "steady": _steady,
}


@dataclass(frozen=True)
class History:
    hours: np.ndarray
    values: np.ndarray
    stds: np.ndarray
    true_life: float  # from the last window to the crossing (inf: never)


def history(law: str, seed: int, n: int = 20, span_h: float = 190.0, std: float = 3e-4) -> History:
    """``n`` windows over ``span_h`` flight hours of ``law``, crossing 20–60 h after the last (a steady one
    never), each estimate with noise at its stated ``std`` (±30 % from window to window)."""
    rng = np.random.default_rng(seed)
    hours = np.sort(rng.uniform(0.0, span_h, n))
    hours[0], hours[-1] = 0.0, span_h
    crossing = span_h + rng.uniform(20.0, 60.0)
    curve = LAWS[law](crossing)
    stds = std * rng.uniform(0.7, 1.3, n)
    values = curve(hours) + stds * rng.standard_normal(n)
    return History(hours, values, stds, np.inf if law == "steady" else crossing - span_h)
