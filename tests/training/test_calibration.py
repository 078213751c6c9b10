"""Round trips of the calibration loop: windows simulated with an effect the loop is not told about."""

import numpy as np
import pytest

from sim.effects import EffectSet
from sim.params import HealthParams
from sim.synthetic import synthetic_window
from training.calibration.calibrate import Calibrator
from training.calibration.channels import held_direction, motor_angle_rad
from training.calibration.library import refined
from training.calibration.selection import integrated_time
from training.pipeline import PipelineConfig

SMALL = PipelineConfig(n_simulations=120, n_timesteps=250, hidden_units=30, check_windows=8)
TRUTH = {"FDJ": 0.053, "eta_O": 0.8}


def calibrate(effects: dict, seeds=(11,)) -> dict:
    health = HealthParams.single(0.1, TRUTH["FDJ"], TRUTH["eta_O"])
    windows = [synthetic_window(health, seed=s, effects=EffectSet(effects)) for s in seeds]  # realistic noise
    return Calibrator(SMALL).fit(windows, TRUTH).report_


def test_clean_windows_select_nothing():
    report = calibrate({}, seeds=(11, 12))
    assert report["selected_effect"] is None
    assert report["schema"] == "ema-calibration/1"
    assert report["estimates_after"] == report["estimates_before"]
    assert len(report["candidates"]) == 8  # every candidate is scored and reported


@pytest.mark.parametrize(
    ("effect", "parameters", "key", "tolerance"),
    [
        ("hinge_moment_bias", {"bias_nm": 15.0}, "bias_nm", 0.05),
        ("viscous", {"coefficient_nms": 5e-5}, "coefficient_nms", 0.15),
        ("backlash", {"extra_rad": 0.004}, "extra_rad", 0.15),
        ("position_friction", {"amplitude_nm": 0.05}, "amplitude_nm", 0.15),
    ],
)
def test_the_undeclared_effect_is_found_and_the_estimates_recover(effect, parameters, key, tolerance):
    report = calibrate({effect: parameters})
    assert report["selected_effect"] == effect, report["selection"]["reason"]
    assert report["selected_parameters"][key] == pytest.approx(parameters[key], rel=tolerance)
    worst_before = max(report["error_pct_before"].values())
    worst_after = max(report["error_pct_after"].values())
    assert worst_after < 0.5 * worst_before or worst_after < 0.6  # % : well below, or at the noise floor
    assert report["residual_rms_after"]["residual_torque"] <= report["residual_rms_before"]["residual_torque"]


def test_a_current_scale_is_found_and_its_twin_reported():
    report = calibrate({"torque_constant": {"gain": 0.92}})
    assert report["selected_effect"] == "torque_constant"
    assert "current_sensor_gain" in report["selection"]["indistinguishable_from"]  # same trace in T_R
    assert report["error_pct_after"]["FDJ"] < 0.5 * report["error_pct_before"]["FDJ"]


def test_no_wrong_name_is_forced():
    # Stribeck friction at ω_s = 200 rad/s looks much like viscous friction in these windows.
    report = calibrate({"stribeck": {"amplitude_nm": 0.03, "speed_radps": 200.0}})
    if report["selected_effect"] != "stribeck":
        assert report["selected_effect"] is None
        assert report["unexplained_structure"]["variable"] == "speed_radps"


def test_integrated_time_of_white_and_smoothed_noise():
    noise = np.random.default_rng(0).normal(size=20_000)
    assert integrated_time(noise, 200) == pytest.approx(1.0, abs=0.3)
    smoothed = np.convolve(noise, np.ones(20) / 20, mode="valid")
    assert 10 < integrated_time(smoothed, 200) < 30


def test_motor_angle_and_held_direction():
    speed = np.array([0.0, 10.0, 10.0, 0.0, 0.0, -10.0, 0.0])
    np.testing.assert_array_equal(held_direction(speed, 5.0), [1, 1, 1, 1, 1, -1, -1])
    angle = motor_angle_rad(np.full(10, 100.0), np.zeros(10), 1000.0, 500.0)
    np.testing.assert_allclose(np.diff(angle), 0.1)


def test_refinements_correct_in_each_effects_algebra():
    assert refined("viscous", {"coefficient_nms": 4e-5}, {"coefficient_nms": 1e-5})["coefficient_nms"] == 5e-5
    assert refined("torque_constant", {"gain": 0.9}, {"gain": 0.98})["gain"] == pytest.approx(0.88)
    stribeck = refined(
        "stribeck", {"amplitude_nm": 0.02, "speed_radps": 40.0}, {"amplitude_nm": 0.01, "speed_radps": 40.0}
    )
    assert stribeck == pytest.approx({"amplitude_nm": 0.03, "speed_radps": 40.0})


def test_two_undeclared_effects_are_both_found():
    report = calibrate({"hinge_moment_bias": {"bias_nm": 12.0}, "viscous": {"coefficient_nms": 5e-5}}, seeds=(11, 12))
    assert set(report["selected_effects"]) == {"hinge_moment_bias", "viscous"}
    assert report["effects"]["hinge_moment_bias"]["bias_nm"] == pytest.approx(12.0, rel=0.05)
    assert report["effects"]["viscous"]["coefficient_nms"] == pytest.approx(5e-5, rel=0.2)
    assert report["error_pct_after"]["FDJ"] < 0.2 * report["error_pct_before"]["FDJ"]
    assert len(report["selection_steps"]) == 2
