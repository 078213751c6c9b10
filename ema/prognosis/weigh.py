"""Which degradation law to believe: the one that predicts the later windows from the earlier ones.

A prognosis extrapolates, so a law is scored on extrapolation: the history is cut at several of its
later windows, each law is drawn through the windows before the cut (``ema.prognosis.laws``) and scored by the
log density it gives the windows after it (each with its own noise, σ² + τ²). A law that follows the
past by bending towards its noise predicts the next windows badly, and one too stiff for wear that
speeds up predicts them too low: the scores weigh both. The weights are the scores' softmax over the
laws, tempered (``TEMPER``) so that laws that predict about as well share the weight: the remaining
life then carries the uncertainty of the law as well as its coefficients'.

Where even the weighed laws missed the later windows by more than they promised, the misses grow with
how far ahead they reached: a slope of error per unit of time ahead, ``drift``, read from the misses
beyond their predicted spread. The forecast carries it as a random slope on every curve
(``ema.prognosis.forecast``): no law of the code follows such wear exactly, and the interval says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.prognosis.laws import LAWS, LawCurve, law_curve

MIN_LAW_WINDOWS = 6  # fewer: the line alone (a law can only be told from another on more)
FIRST_CUT = 0.75  # the earliest cut, as a share of the history: the later windows tell where it goes now
CUTS = 6  # cuts at most, evenly between FIRST_CUT and the last window but one
TEMPER = 4.0  # the scores are divided by this: two laws whose scores differ by ln 2·TEMPER weigh 2 : 1


@dataclass(frozen=True)
class Weighed:
    """Every law drawn through the whole history, its weight and extrapolation score, and the drift of the weighed
    forecast's misses per unit of s ahead (0 where it held the later windows as it said it would)."""

    curves: list[LawCurve]
    weights: np.ndarray  # (laws,), summing to 1
    scores: np.ndarray  # (laws,) mean log density of the later windows over the cuts (nan: not scored)
    drift: float = 0.0  # std of the forecast's error slope, per unit of s


@dataclass(frozen=True)
class Later:
    """One law's prediction, from the windows before a cut, of the windows after it."""

    mean: np.ndarray
    variance: np.ndarray  # the curve's, plus each window's noise
    observed: np.ndarray
    ahead: np.ndarray  # s past the cut's last window

    def log_density(self) -> float:
        z2 = (self.observed - self.mean) ** 2 / self.variance
        return float(np.mean(-0.5 * (np.log(2 * np.pi * self.variance) + z2)))


def cut_points(n: int) -> list[int]:
    """Where the history is cut: the number of windows each scoring curve sees."""
    first = max(MIN_LAW_WINDOWS - 1, int(np.ceil(FIRST_CUT * n)))
    return sorted({int(k) for k in np.linspace(first, n - 1, CUTS).round()} - {n})


def later(law_index: int, s: np.ndarray, y: np.ndarray, weight: np.ndarray, k: int) -> Later:
    """The law drawn through the first ``k`` windows, predicting the rest."""
    curve = law_curve(LAWS[law_index], s[:k], y[:k], weight[:k])
    mean, variance = curve.predictive(s[k:])
    noise = 1.0 / np.maximum(weight[k:], 1e-300)
    return Later(mean, variance + noise, y[k:], s[k:] - s[k - 1])


def drift(predictions: list[list[Later]], weights: np.ndarray) -> float:
    """The std of the error slope per unit of s ahead that the weighed predictions' misses show beyond their
    own spread (0 where they kept within it)."""
    excess, reach = [], []
    for by_law in zip(*predictions, strict=True):  # per cut, every law's prediction
        mean = sum(w * p.mean for w, p in zip(weights, by_law, strict=True))
        variance = sum(w * (p.variance + (p.mean - mean) ** 2) for w, p in zip(weights, by_law, strict=True))
        excess.append((by_law[0].observed - mean) ** 2 - variance)
        reach.append(by_law[0].ahead ** 2)
    slope2 = float(np.sum(np.concatenate(excess)) / max(np.sum(np.concatenate(reach)), 1e-300))
    return float(np.sqrt(max(slope2, 0.0)))


def weigh(s: np.ndarray, y: np.ndarray, weight: np.ndarray) -> Weighed:
    """Every law drawn through the history, weighed by how well it predicts later windows from earlier ones."""
    curves = [law_curve(law, s, y, weight) for law in LAWS]
    if len(s) < MIN_LAW_WINDOWS:
        only = np.array([1.0 if law.name == "linear" else 0.0 for law in LAWS])
        return Weighed(curves, only, np.full(len(LAWS), np.nan))
    cuts = cut_points(len(s))
    predictions = [[later(i, s, y, weight, k) for k in cuts] for i in range(len(LAWS))]
    scores = np.array([sum(p.log_density() for p in by_cut) for by_cut in predictions])
    tempered = scores / TEMPER
    weights = np.exp(tempered - tempered.max())
    weights /= weights.sum()
    return Weighed(curves, weights, scores / len(cuts), drift(predictions, weights))
