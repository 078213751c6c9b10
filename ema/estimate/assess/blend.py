"""Pick or blend the network and the physics baseline, per parameter, by their measured errors.

Both estimators are run on the same held-out simulated windows (the window's own command, noise
and flight condition, fresh health draws). For each parameter the blend weight w minimizes the
mean squared error of w·network + (1 − w)·baseline on those windows (closed form, clipped to
[0, 1], so "use only the better one" is a special case); the combined estimate's std is the RMS
error of the blend there. This is how "the best estimator for each parameter" is decided on data,
not by assumption.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.estimate.stats import rms


@dataclass(frozen=True)
class Blend:
    weight_network: float  # w in [0, 1]
    rms_error: float  # of the blend on the check windows, in the parameter's unit
    rms_error_network: float
    rms_error_baseline: float

    def apply(self, network: float, baseline: float) -> float:
        return self.weight_network * network + (1.0 - self.weight_network) * baseline


def best_blend(truth: np.ndarray, network: np.ndarray, baseline: np.ndarray) -> Blend:
    """The MSE-optimal convex weight from paired estimates of one parameter on check windows."""
    e_net, e_base = network - truth, baseline - truth
    difference = e_net - e_base
    denominator = float(difference @ difference)
    weight = 0.5 if denominator == 0.0 else float(np.clip(-(e_base @ difference) / denominator, 0.0, 1.0))
    blended = weight * e_net + (1.0 - weight) * e_base

    return Blend(weight, rms(blended), rms(e_net), rms(e_base))
