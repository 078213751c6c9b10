"""The pipeline's sizes: each default and bound, defined here once.

Plain data, so that the CLI's help can show them without importing pydantic or numpy;
``ema.estimate.config.PipelineConfig`` (the validated object every layer passes around) is built
from this table.
"""

from __future__ import annotations

from typing import NamedTuple


class Size(NamedTuple):
    default: int
    low: int
    high: int
    description: str


SIZES = {
    "n_simulations": Size(64, 16, 4000, "simulations the network trains on"),
    "check_simulations": Size(24, 8, 1000, "held-out simulations that score the estimators"),
    "n_timesteps": Size(500, 10, 10_000, "network input timesteps (bins of the window)"),
    "hidden_units": Size(100, 1, 2000, "hidden neurons"),
    "members": Size(1, 1, 20, "networks in the ensemble"),
    "seed": Size(0, 0, 2**32 - 1, "seed of the dataset and the training"),
}
