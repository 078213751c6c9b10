import numpy as np
import pytest

from ema.kinds.rotary.dataset import simulate_noisy
from ema.kinds.rotary.physics.scenario import initial_state, scenario_from_window
from ema.kinds.rotary.simulator.batch import InitialState
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.noise import NO_NOISE, SensorNoise
from ema.model.params import HealthParams
from ema.model.window import window_from_dict
from tests.foreign.windows import draw


def test_a_clean_window_is_reproduced_by_its_own_scenario():
    truth = HealthParams.single(0.11, 0.055, 0.8)
    window = synthetic_window(truth, seed=4, duration_s=0.1, noise=NO_NOISE)
    replay = scenario_from_window(window, drive=THESIS.params, hinge=THESIS.hinge).simulate(truth).simulation(0)
    # Command through knots and back, the start through a parabola, the load from the log: tiny differences.
    assert np.abs(replay["position_deg"] - window.signals["position_deg"]).max() < 0.02
    assert np.abs(replay["current_a"] - window.signals["current_a"]).mean() < 0.2
    assert np.abs(replay["hinge_moment_nm"] - window.signals["hinge_moment_nm"]).max() < 1.0


def test_initial_state_is_read_through_the_noise():
    window = synthetic_window(HealthParams.single(), seed=5, duration_s=0.05)
    state = initial_state(window, drive=THESIS.params)
    assert state.position_deg == pytest.approx(0.0, abs=0.02)
    assert state.motor_speed_radps == pytest.approx(0.0, abs=2.0)
    assert isinstance(state, InitialState)


def _noise_read_at(window, health: HealthParams) -> SensorNoise:
    """The window's noise as the dataset reads it: against the batch's clean lane at ``health``."""
    scenario = scenario_from_window(window, drive=THESIS.params, hinge=THESIS.hinge)
    return simulate_noisy(scenario, health, window, health, seed=0, clean_last=1).noise


def test_window_noise_is_estimated_against_the_clean_model():
    window = synthetic_window(HealthParams.single(), seed=6, duration_s=0.2)
    estimated = _noise_read_at(window, HealthParams.single())
    truth = SensorNoise()
    assert estimated.motor_speed_radps == pytest.approx(truth.motor_speed_radps, rel=0.25)
    assert estimated.current_a == pytest.approx(truth.current_a, rel=0.25)
    assert estimated.hinge_moment_nm == pytest.approx(truth.hinge_moment_nm, rel=0.25)
    clean = synthetic_window(HealthParams.single(), seed=6, duration_s=0.2, noise=NO_NOISE)
    assert _noise_read_at(clean, HealthParams.single()).motor_speed_radps < 0.1


def test_noisy_simulations_are_seeded_and_keep_their_clean_residual():
    window = synthetic_window(HealthParams.single(), seed=7, duration_s=0.05)
    scenario = scenario_from_window(window, drive=THESIS.params, hinge=THESIS.hinge)
    health = HealthParams(np.full(8, 0.1), np.linspace(0.04, 0.06, 8), np.full(8, 0.85))
    a = simulate_noisy(scenario, health, window, HealthParams.single(), 3, 2)
    b = simulate_noisy(scenario, health, window, HealthParams.single(), 3, 2)
    assert a.residual_nm.shape == (8, 500) and a.clean_residual_nm.shape == (2, 500)
    assert a.noise.current_a == pytest.approx(SensorNoise().current_a, rel=0.3)  # the window's own, measured
    np.testing.assert_array_equal(a.residual_nm, b.residual_nm)
    assert not np.array_equal(a.residual_nm[-2:], a.clean_residual_nm)


def test_the_reference_lane_is_its_own_one_lane_run_to_the_bit():
    """What lets the answer's check reuse it: a lane of the batch equals a run of its own (a foreign window)."""
    window = window_from_dict(draw(11, "gust").document)
    scenario = scenario_from_window(window, drive=THESIS.params, hinge=THESIS.hinge)
    health = HealthParams(np.full(40, 0.1), np.linspace(0.04, 0.06, 40), np.linspace(0.7, 0.95, 40))
    reference = HealthParams.single(0.1, 0.052, 0.83)
    kept = simulate_noisy(scenario, health, window, reference, 3, 2)
    alone = scenario.simulate(reference, lanes=1).simulation(0)
    assert kept.reference.identical(reference) and not kept.reference.identical(HealthParams.single(0.1, 0.052, 0.84))
    assert kept.reference_signals.keys() == alone.keys()
    for name, values in alone.items():
        np.testing.assert_array_equal(kept.reference_signals[name], values, err_msg=name)
    simulate_noisy(scenario, health, window, HealthParams.single(0.1, 0.05, 0.9), 3, 2)  # the kept buffer written over
    np.testing.assert_array_equal(kept.reference_signals["current_a"], alone["current_a"])
