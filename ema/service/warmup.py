"""Start-up warm-up: compile (or load from the cache) every kernel and JIT path before serving."""

from __future__ import annotations

from ema.estimate.config import PipelineConfig
from ema.estimate.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.synthetic import synthetic_window

WARM_UP = PipelineConfig(n_simulations=16, check_windows=8, n_timesteps=20, hidden_units=4)


def warm_up() -> None:
    """A tiny pipeline run: simulation kernels, residual, network and the physics fit all exercised once."""
    estimate_window(synthetic_window(HealthParams.single(), seed=0, duration_s=0.05), WARM_UP, actuator=THESIS)
