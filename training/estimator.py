"""Networks trained on a dataset, as an estimator of FDJ, η_O (η_A derived) with an uncertainty.

The uncertainty of an estimate combines two parts in quadrature, in normalized units: the spread
of an ensemble of independently seeded networks (each with its own split), and the error the
networks make on their held-out test simulations, which carry the same sensor noise as the
window. With one member only the second part remains: an honest global error bar, not a
per-window one.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from sim.checks import InputError
from sim.params import HealthRanges, eta_a_from_eta_o
from training.dataset import Dataset, denormalize_targets
from training.network import FitResult, TrainConfig, fit, predict


@dataclass(frozen=True)
class Estimate:
    value: float
    std: float


class NetworkEstimator:
    """scikit-learn shape: settings in ``__init__``, ``fit(dataset)`` returns self, learned values end in ``_``."""

    def __init__(self, train: TrainConfig = TrainConfig(), members: int = 1) -> None:
        if not 1 <= members <= 20:
            raise InputError("members", f"must be in [1, 20], got {members}")
        self.train = train
        self.members = members

    def fit(self, dataset: Dataset) -> NetworkEstimator:
        self.fits_: list[FitResult] = [
            fit(dataset.inputs, dataset.targets, replace(self.train, seed=self.train.seed + member))
            for member in range(self.members)
        ]
        self.ranges_: HealthRanges = dataset.config.ranges
        return self

    def predict_normalized(self, inputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean (N, 2) and std (N, 2) of the normalized FDJ, η_O predictions."""
        predictions = np.stack([predict(f.model, inputs) for f in self.fits_])  # (members, N, 2)
        spread = predictions.var(axis=0) if self.members > 1 else np.zeros(predictions.shape[1:])
        test_error = np.mean([f.test_mse_per_target for f in self.fits_], axis=0)  # (2,)
        return predictions.mean(axis=0), np.sqrt(spread + test_error)

    def estimate(self, inputs: np.ndarray) -> dict[str, Estimate]:
        """FDJ [N·m], η_O and η_A for one window's inputs (1, F), each with a std in its own unit."""
        mean, std = self.predict_normalized(np.atleast_2d(inputs))
        values = denormalize_targets(mean, self.ranges_)
        fdj_width = self.ranges_.fdj_nm[1] - self.ranges_.fdj_nm[0]
        eta_width = self.ranges_.eta_o[1] - self.ranges_.eta_o[0]
        eta_o, eta_o_std = float(values["eta_O"][0]), float(std[0, 1] * eta_width)
        slope = (eta_a_from_eta_o(eta_o + 1e-6) - eta_a_from_eta_o(eta_o - 1e-6)) / 2e-6  # Eq. 3.4 is smooth
        return {
            "FDJ": Estimate(float(values["FDJ"][0]), float(std[0, 0] * fdj_width)),
            "eta_O": Estimate(eta_o, eta_o_std),
            "eta_A": Estimate(float(values["eta_A"][0]), float(abs(slope) * eta_o_std)),
        }
