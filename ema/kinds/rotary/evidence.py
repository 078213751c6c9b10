"""How the rotary's stages weigh one reading of a window against another: block-jackknife stds over its
samples, the likelihood ratio of two solutions of Eq. 5.1 by their equation errors, the prior odds of a
departure a window leans to without showing it."""

from __future__ import annotations

import numpy as np

from ema.kinds.rotary.simulator.residual import DERIVATIVE_SPAN_S, kernel_samples

JACKKNIFE_BLOCKS = 10


def jackknife_std(estimates: np.ndarray) -> np.ndarray:
    """Std of the full-sample estimate from (N, B, …) leave-one-block-out estimates."""
    b = estimates.shape[1]
    return np.sqrt((b - 1) / b * np.sum((estimates - estimates.mean(axis=1, keepdims=True)) ** 2, axis=1))


# A departure a window leans to without showing it (a hinge moment out of step, a viscous coefficient off the
# document's) is weighed against the document's reading with these prior odds (which also pay for trying several: ten
# lags, one C), into the stds only; a note says so from this weight.
UNDECIDED_PRIOR_LOG_ODDS = -4.0


UNDECIDED_NOTE_WEIGHT = 0.1


def rms_log_likelihood_ratio(
    worse_rms: float, better_rms: float, n_sliding: float, rate: float, *, resolution_nm: float
) -> float:
    """ln of the likelihood ratio of two solutions of one window's ``n_sliding`` samples by their RMS equation
    errors, with one independent value per reconstruction kernel (the kernel smooths both sides of Eq. 5.1), each
    error never under the model's ``resolution_nm`` (``RESOLUTION_SHARE``): on a log without noise, what a solution
    gains below it is the model's own error, not the window's evidence."""
    worse, better = np.hypot(worse_rms, resolution_nm), np.hypot(better_rms, resolution_nm)
    return n_sliding / kernel_samples(rate, DERIVATIVE_SPAN_S) * float(np.log(worse / better))
