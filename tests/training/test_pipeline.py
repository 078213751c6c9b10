"""Round trip: a window simulated with a known truth, estimated by the whole pipeline."""

import pytest

from sim.params import HealthParams
from sim.synthetic import synthetic_window
from training.pipeline import PipelineConfig, estimate_window


def _config(**overrides):
    return PipelineConfig(**{"n_simulations": 120, "n_timesteps": 250, "hidden_units": 30, **overrides})


def test_pipeline_recovers_the_truth_within_its_stated_uncertainty():
    window = synthetic_window(HealthParams.single(0.1, 0.054, 0.78), seed=21, duration_s=0.25)
    result = estimate_window(window, _config())
    estimates = result["estimates"]
    assert estimates["FDJ"]["value"] == pytest.approx(0.054, abs=max(4 * estimates["FDJ"]["std"], 2e-4))
    assert estimates["eta_O"]["value"] == pytest.approx(0.78, abs=max(4 * estimates["eta_O"]["std"], 3e-3))
    assert estimates["FSJ"] is None and "break-away" in result["fsj_note"]
    assert estimates["FDJ"]["drift_pct"] == pytest.approx(100 * (estimates["FDJ"]["value"] / 0.05 - 1))
    assert set(result["timings_s"]) == {"simulate", "train", "predict", "total"}
    assert result["schema"] == "ema-estimate/1"


@pytest.mark.slow
def test_pipeline_at_default_sizes_beats_half_a_percent():
    window = synthetic_window(HealthParams.single(0.1, 0.046, 0.91), seed=22)
    estimates = estimate_window(window)["estimates"]
    assert estimates["FDJ"]["value"] == pytest.approx(0.046, rel=0.005)
    assert estimates["eta_O"]["value"] == pytest.approx(0.91, rel=0.005)
