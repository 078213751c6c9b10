"""Statistics every stage shares: block-jackknife stds, likelihood ratios of two solutions, posterior weights of two
stories, and how decisive a difference must be."""

from __future__ import annotations

import numpy as np

from ema.model.residual import DERIVATIVE_SPAN_S, kernel_samples

JACKKNIFE_BLOCKS = 10
DECISIVE_Z = 4.0  # stds by which a reading must explain a window better than the document's before it is taken
MAX_RATIO = 2.0  # every kind's check: an output error within twice its noise floor is reproduced
SIGN_STDS = 3.0  # a constant that must be positive read this many stds below zero: the log's signs, not its noise
# The share of the drive's effort (the motor torque k_T·I, a servo's force) under which a model's error is no
# evidence: the document's k_T alone moves 0.1 %/K with the magnets' temperature, and ema's integration of a closed
# loop leaves 0.1 % of the force against an exact solution. Equation and output errors are read against a noise
# never under it, so a log without sensor noise is judged as one with a little, never as an exact model's.
RESOLUTION_SHARE = 0.002


def jackknife_std(estimates: np.ndarray) -> np.ndarray:
    """Std of the full-sample estimate from (N, B, …) leave-one-block-out estimates."""
    b = estimates.shape[1]
    return np.sqrt((b - 1) / b * np.sum((estimates - estimates.mean(axis=1, keepdims=True)) ** 2, axis=1))


# A departure a window leans to without showing it (a hinge moment out of step, a viscous coefficient off the
# document's) is weighed against the document's reading with these prior odds (which also pay for trying several: ten
# lags, one C), into the stds only; a note says so from this weight.
UNDECIDED_PRIOR_LOG_ODDS = -4.0
UNDECIDED_NOTE_WEIGHT = 0.1


def odds_weight(log_odds: float) -> float:
    """The posterior weight of a story whose ln posterior odds against its rival are ``log_odds`` (clipped
    where exp would overflow)."""
    return float(1.0 / (1.0 + np.exp(-np.clip(log_odds, -50.0, 50.0))))


def rms(values: np.ndarray) -> float:
    """The root mean square of ``values`` (0 for none)."""
    return float(np.sqrt(np.mean(values**2))) if len(values) else 0.0


def rms_log_likelihood_ratio(
    worse_rms: float, better_rms: float, n_sliding: float, rate: float, *, resolution_nm: float
) -> float:
    """ln of the likelihood ratio of two solutions of one window's ``n_sliding`` samples by their RMS equation
    errors, with one independent value per reconstruction kernel (the kernel smooths both sides of Eq. 5.1), each
    error never under the model's ``resolution_nm`` (``RESOLUTION_SHARE``): on a log without noise, what a solution
    gains below it is the model's own error, not the window's evidence."""
    worse, better = np.hypot(worse_rms, resolution_nm), np.hypot(better_rms, resolution_nm)
    return n_sliding / kernel_samples(rate, DERIVATIVE_SPAN_S) * float(np.log(worse / better))


def below_zero(values: dict[str, float], stds: dict[str, float]) -> list[str]:
    """The names whose value lies more than ``SIGN_STDS`` stds below zero: of constants that must be positive (a
    mass, a friction that opposes the motion), what no noise explains, and a log's sign or time reversed does."""
    return [name for name in values if values[name] < -SIGN_STDS * stds[name]]
