import numpy as np
import pytest

from sim.batch import InitialState
from sim.noise import NO_NOISE, SensorNoise
from sim.params import DEFAULT_RANGES, HealthParams
from sim.synthetic import synthetic_window
from training.dataset import (
    DatasetConfig,
    build_dataset,
    denormalize_targets,
    initial_state,
    normalize_targets,
    scenario_from_window,
    window_noise,
)


def test_targets_round_trip_through_normalization():
    health = HealthParams.uniform(50, DEFAULT_RANGES, np.random.default_rng(0))
    normalized = normalize_targets(health, DEFAULT_RANGES)
    assert normalized.min() >= 0.0 and normalized.max() <= 1.0
    back = denormalize_targets(normalized, DEFAULT_RANGES)
    np.testing.assert_allclose(back["FDJ"], health.fdj_nm)
    np.testing.assert_allclose(back["eta_O"], health.eta_o)
    np.testing.assert_allclose(back["eta_A"], health.eta_a())


def test_a_clean_window_is_reproduced_by_its_own_scenario():
    truth = HealthParams.single(0.11, 0.055, 0.8)
    window = synthetic_window(truth, seed=4, duration_s=0.1, noise=NO_NOISE)
    replay = scenario_from_window(window).simulate(truth).simulation(0)
    # The command goes through knots and back, the start through a line fit: only tiny differences remain.
    assert np.abs(replay["position_deg"] - window.signals["position_deg"]).max() < 0.02
    assert np.abs(replay["current_a"] - window.signals["current_a"]).mean() < 0.2


def test_initial_state_is_read_through_the_noise():
    window = synthetic_window(HealthParams.single(), seed=5, duration_s=0.05)
    state = initial_state(window)
    assert state.position_deg == pytest.approx(0.0, abs=0.02)
    assert state.motor_speed_radps == pytest.approx(0.0, abs=2.0)
    assert isinstance(state, InitialState)


def test_window_noise_is_estimated_against_the_clean_model():
    window = synthetic_window(HealthParams.single(), seed=6, duration_s=0.2)
    estimated = window_noise(window, scenario_from_window(window))
    truth = SensorNoise()
    assert estimated.motor_speed_radps == pytest.approx(truth.motor_speed_radps, rel=0.25)
    assert estimated.current_a == pytest.approx(truth.current_a, rel=0.25)
    assert estimated.hinge_moment_nm == pytest.approx(truth.hinge_moment_nm, rel=0.25)
    clean = synthetic_window(HealthParams.single(), seed=6, duration_s=0.2, noise=NO_NOISE)
    assert window_noise(clean, scenario_from_window(clean)).motor_speed_radps < 0.1


def test_dataset_is_seeded_and_shaped():
    window = synthetic_window(HealthParams.single(), seed=7, duration_s=0.05)
    scenario = scenario_from_window(window)
    config = DatasetConfig(n_simulations=24, n_timesteps=50, input_set="input_map", seed=3)
    a, b = build_dataset(scenario, config, SensorNoise()), build_dataset(scenario, config, SensorNoise())
    assert a.inputs.shape == (24, 150) and a.targets.shape == (24, 2)
    np.testing.assert_array_equal(a.inputs, b.inputs)
