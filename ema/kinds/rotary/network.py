"""The rotary's network: a window's network trained on its simulations to FDJ and η_O, read back in their units."""

from __future__ import annotations

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.learn.estimator import trained
from ema.kinds.rotary.box import Box


class NetworkEstimator:
    """FDJ and η_O through the dataset's ``Box`` by a window's network (``trained``), in their units.
    scikit-learn shape: settings in ``__init__``, ``fit`` returns self, learned values end in ``_``."""

    def __init__(self, config: PipelineConfig) -> None:
        self.config = config

    def fit(self, inputs: np.ndarray, fdj_nm: np.ndarray, eta_o: np.ndarray, box: Box) -> NetworkEstimator:
        self.regressor_ = trained(inputs, box.normalize(fdj_nm, eta_o), self.config)
        self.members_ = self.regressor_.members_
        self.box_ = box
        return self

    def predict_unit(self, inputs: np.ndarray) -> np.ndarray:
        """(N, 2) FDJ, η_O in box units, the members' mean, unclipped."""
        return self.regressor_.predict_unit(inputs)

    def predict(self, inputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """FDJ [N·m] and η_O for each row of ``inputs`` (N, F)."""
        return self.box_.denormalize(self.predict_unit(inputs))
