"""The Eq. 5.1 least-squares fit, on our windows and on foreign ones."""

import numpy as np
import pytest

from ema.kinds.rotary.physics.friction import SolveSettings, solve_friction, solve_window
from ema.kinds.rotary.simulator.batch import simulate_batch
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.kinds.rotary.simulator.sensor_noise import add_sensor_noise
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.noise import NO_NOISE, SensorNoise
from ema.model.params import DriveConstants, HealthParams
from ema.model.window import window_from_dict
from tests.foreign.windows import draw


@pytest.mark.parametrize(("noise", "tolerance"), [(NO_NOISE, 0.004), (SensorNoise(), 0.015)])
def test_recovers_fdj_and_eta_o_from_an_in_flight_window(noise, tolerance):
    window = synthetic_window(HealthParams.single(0.1, 0.057, 0.74), seed=9, noise=noise)
    solved = solve_window(window.signals, window.sample_rate_hz, drive=THESIS.params)
    assert solved.fdj_nm[0] == pytest.approx(0.057, rel=tolerance)
    assert solved.eta_o[0] == pytest.approx(0.74, rel=tolerance)


@pytest.mark.parametrize("seed", [21, 22, 23])
def test_recovers_the_truth_of_foreign_windows_within_a_few_jackknife_stds(seed):
    window = draw(seed, ("doublet", "cruise", "steps")[seed % 3])
    signals = window_from_dict(window.document).signals
    solved = solve_window(signals, 10_000.0, drive=THESIS.params)
    assert abs(solved.fdj_nm[0] - window.truth["FDJ"]) < 5 * solved.fdj_std_nm[0]
    assert abs(solved.eta_o[0] - window.truth["eta_O"]) < 5 * solved.eta_o_std[0]
    assert solved.fdj_nm[0] == pytest.approx(window.truth["FDJ"], rel=0.02)


def test_a_batch_fits_each_window_as_alone_and_jackknife_stds_are_honest():
    health = HealthParams(np.full(40, 0.1), np.full(40, 0.052), np.full(40, 0.8))
    window = synthetic_window(HealthParams.single(0.1, 0.052, 0.8), seed=4)
    from ema.kinds.rotary.physics.scenario import scenario_from_window

    clean = scenario_from_window(window, drive=THESIS.params, hinge=THESIS.hinge).simulate(health).signals
    noisy = add_sensor_noise(clean, SensorNoise(), np.random.default_rng(1))
    batch = solve_friction(noisy, 10_000.0, drive=THESIS.params)
    single = solve_friction({k: v[3] for k, v in noisy.items()}, 10_000.0, drive=THESIS.params)
    assert batch.fdj_nm[3] == pytest.approx(single.fdj_nm[0], rel=1e-12)
    # The spread of estimates over noise draws and the jackknife std agree within a factor of two.
    spread = np.std(batch.fdj_nm)
    assert 0.5 < np.median(batch.fdj_std_nm) / spread < 2.0


def test_too_little_motion_is_refused_naming_the_signals():
    result = simulate_batch(np.zeros(1001), HealthParams.single(), GroundLoad(0.0), drive=THESIS.params)
    signals = add_sensor_noise(result.simulation(0), SensorNoise(), np.random.default_rng(0))
    with pytest.raises(InputError) as error:
        solve_window(signals, 10_000.0, drive=THESIS.params)
    assert error.value.field == "signals" and "sliding" in error.value.message


def test_settings_are_checked():
    with pytest.raises(InputError, match="min_speed_share"):
        SolveSettings(min_speed_share=-1)


def test_a_constant_torque_is_fitted_beside_friction_and_moves_nothing_else():
    """A current i₀ off zero adds exactly k_T·i₀ to T_R: the offset fit reads it and FDJ, η_O stay put."""
    window = synthetic_window(HealthParams.single(0.1, 0.052, 0.8), seed=5, noise=SensorNoise())
    settings = SolveSettings(offset=True)
    plain = solve_friction(window.signals, 10_000.0, settings=settings, drive=THESIS.params)
    shifted = dict(window.signals, current_a=window.signals["current_a"] + 0.1)
    off = solve_friction(shifted, 10_000.0, settings=settings, drive=THESIS.params)
    # exactly, but for the few samples where k_T·I is clipped at the motor's peak torque
    assert off.term("offset")[0] - plain.term("offset")[0] == pytest.approx(0.1 * 0.0752, rel=5e-3)
    assert off.fdj_nm[0] == pytest.approx(plain.fdj_nm[0], rel=1e-3)
    assert off.eta_o[0] == pytest.approx(plain.eta_o[0], rel=1e-3)
    assert abs(plain.term("offset")[0]) < 3 * plain.term_std("offset")[0]  # none there: zero within its std
    assert solve_friction(shifted, 10_000.0, drive=THESIS.params).term("offset")[0] == 0.0  # not asked: not fitted


def test_an_offset_is_not_fitted_where_the_motion_goes_one_way():
    window = synthetic_window(HealthParams.single(0.1, 0.052, 0.8), seed=5)
    one_way = dict(window.signals, motor_speed_radps=np.abs(window.signals["motor_speed_radps"]))
    assert (
        solve_friction(one_way, 10_000.0, settings=SolveSettings(offset=True), drive=THESIS.params).term("offset")[0]
        == 0.0
    )


def test_a_viscous_coefficient_beyond_the_actuators_is_read_exactly_and_moves_nothing_else():
    """Motor torque ΔC·ω more (the current k_T⁻¹·ΔC·ω more): the viscous fit reads ΔC, FDJ and η_O stay put."""
    window = synthetic_window(HealthParams.single(0.1, 0.052, 0.8), seed=5, noise=SensorNoise())
    unclipped = DriveConstants(max_motor_torque_nm=100.0)  # the extra torque is not lost where the motor saturates
    settings = SolveSettings(offset=True, viscous=True)
    plain = solve_friction(window.signals, 10_000.0, unclipped, settings)
    extra = 3e-5 * window.signals["motor_speed_radps"] / 0.0752
    more = solve_friction(
        dict(window.signals, current_a=window.signals["current_a"] + extra), 10_000.0, unclipped, settings
    )
    assert more.term("viscous")[0] - plain.term("viscous")[0] == pytest.approx(3e-5, rel=1e-6)
    assert more.fdj_nm[0] == pytest.approx(plain.fdj_nm[0], rel=1e-6)
    assert more.eta_o[0] == pytest.approx(plain.eta_o[0], rel=1e-6)
    assert abs(plain.term("viscous")[0]) < 4 * plain.term_std("viscous")[0]  # the spec's C: no change within its std


def test_a_scaled_motor_torque_is_read_exactly_and_moves_nothing_else():
    """A current logged 3 % low (or k_T 3 % above the spec's): the scale fit reads γ = 1/0.97 − 1, FDJ and η_O
    stay put; without it, FDJ moves by several % of its range."""
    window = synthetic_window(HealthParams.single(0.1, 0.052, 0.8), seed=5, noise=SensorNoise())
    unclipped = DriveConstants(max_motor_torque_nm=100.0)  # no sample saturated: the scale holds everywhere
    settings = SolveSettings(offset=True, torque_scale=True)
    plain = solve_friction(window.signals, 10_000.0, unclipped, settings)
    low = dict(window.signals, current_a=0.97 * window.signals["current_a"])
    scaled = solve_friction(low, 10_000.0, unclipped, settings)
    assert (1 + scaled.term("torque_scale")[0]) / (1 + plain.term("torque_scale")[0]) == pytest.approx(
        1 / 0.97, rel=1e-9
    )
    assert scaled.fdj_nm[0] == pytest.approx(plain.fdj_nm[0], rel=1e-6)
    assert scaled.eta_o[0] == pytest.approx(plain.eta_o[0], rel=1e-6)
    assert (
        abs(plain.term("torque_scale")[0]) < 4 * plain.term_std("torque_scale")[0]
    )  # the spec's k_T: no scale within its std
    unread = solve_friction(low, 10_000.0, unclipped)
    assert abs(unread.fdj_nm[0] - plain.fdj_nm[0]) > 0.05 * 0.02
