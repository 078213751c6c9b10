"""A window's networks, as an estimator every kind trains on its simulations.

With several members (independently seeded, each with its own split) the prediction is their mean. Targets are in
the units of the kind's dataset box, 0 and 1 at its edges (the rotary's FDJ and η_O, a servo's constants).
Predictions are returned unclipped in those units too, so that the caller sees when the network leaves the region
it was trained on.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ema.estimate.config import PipelineConfig
from ema.estimate.learn.network import LearnConfig, LearnedNetwork, learn_network
from ema.model.checks import InputError

WINDOW_LEARNING = LearnConfig(max_epochs=60, max_validation_failures=6)  # a window's own few dozen simulations


def window_learning(config: PipelineConfig) -> LearnConfig:
    """How every kind trains a window's network: ``WINDOW_LEARNING`` at the request's hidden units and seed."""
    return replace(WINDOW_LEARNING, hidden=config.hidden_units, seed=config.seed)


def trained(inputs: np.ndarray, unit_targets: np.ndarray, config: PipelineConfig) -> NetworkRegressor:
    """A window's network trained on its simulations (``inputs``, targets in box units), as ``config`` asks."""
    return NetworkRegressor(window_learning(config), config.members).fit(inputs, unit_targets)


class NetworkRegressor:
    """Networks from inputs to targets already in box units (0 and 1 at the box's edges): the members' mean,
    unclipped. scikit-learn shape: settings in ``__init__``, ``fit`` returns self, learned values end in ``_``."""

    def __init__(self, learn: LearnConfig = LearnConfig(), members: int = 1) -> None:
        self.learn = learn
        self.members = members

    def fit(self, inputs: np.ndarray, unit_targets: np.ndarray) -> NetworkRegressor:
        if not 1 <= self.members <= 20:
            raise InputError("members", f"must be in [1, 20], got {self.members}")
        self.members_: list[LearnedNetwork] = [
            learn_network(inputs, unit_targets, replace(self.learn, seed=self.learn.seed + member))
            for member in range(self.members)
        ]
        return self

    def predict_unit(self, inputs: np.ndarray) -> np.ndarray:
        """(N, T) the targets in box units, the members' mean, unclipped."""
        return np.mean([member.model(inputs) for member in self.members_], axis=0)
