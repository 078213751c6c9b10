"""Start-up warm-up: compile (or load from the cache) every kernel and JIT path before serving."""

from __future__ import annotations

from sim.params import HealthParams
from sim.synthetic import synthetic_window
from training.pipeline import PipelineConfig, estimate_window


def warm_up() -> None:
    """A tiny pipeline run: simulation kernels, residual, network and baseline all exercised once."""
    window = synthetic_window(HealthParams.single(), seed=0, duration_s=0.02)
    estimate_window(window, PipelineConfig(n_simulations=20, n_timesteps=20, hidden_units=4, check_windows=8))
