"""Networks trained on a dataset, as an estimator of FDJ and η_O (η_A derived).

With several members (independently seeded, each with its own split) the prediction is their
mean. The uncertainty a result carries is not computed here: the pipeline measures it on
held-out simulated windows with the window's own command, condition and noise
(``training.pipeline``), which covers the network's error and the noise alike.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from sim.checks import InputError
from sim.params import HealthRanges
from training.dataset import Dataset, denormalize_targets
from training.network import FitResult, TrainConfig, fit, predict


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

    def predict_normalized(self, inputs: np.ndarray) -> np.ndarray:
        """(N, 2) normalized FDJ, η_O: the members' mean."""
        return np.mean([predict(f.model, inputs) for f in self.fits_], axis=0)

    def predict(self, inputs: np.ndarray) -> dict[str, np.ndarray]:
        """FDJ [N·m], η_O and η_A (Eq. 3.4) for each row of ``inputs`` (N, F)."""
        return denormalize_targets(self.predict_normalized(np.atleast_2d(inputs)), self.ranges_)
