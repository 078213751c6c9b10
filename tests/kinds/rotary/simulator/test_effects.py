"""Each optional effect leaves the trace its signature promises, and off means exactly off."""

import numpy as np
import pytest

from ema.kinds.rotary.simulator.batch import simulate_batch
from ema.kinds.rotary.simulator.effects import EFFECTS, EffectSet, FrictionTable
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.model.actuator import THESIS
from ema.model.checks import InputError
from ema.model.params import HealthParams
from tests.kinds.rotary.simulator.conftest import ramp_knots

STEADY = slice(1000, 3000)
NOMINAL = HealthParams.single()
KNOTS = ramp_knots(0.0, 10.0, 3000)  # 10°/s: the motor slides at ≈ 87 rad/s
LOAD = GroundLoad(-100.0)


def run(effects: EffectSet = EffectSet()):
    return simulate_batch(KNOTS, NOMINAL, LOAD, effects=effects, drive=THESIS.params)


@pytest.fixture(scope="module")
def base():
    return run()


def test_neutral_parameters_reproduce_the_base_model_exactly(base):
    neutral = EffectSet({name: {key: spec[0] for key, spec in e.parameters.items()} for name, e in EFFECTS.items()})
    result = run(neutral)
    for name in base.signals:
        np.testing.assert_array_equal(result.signals[name], base.signals[name])


def test_hinge_moment_bias_shifts_only_the_measured_hinge_moment(base):
    result = run(EffectSet({"hinge_moment_bias": {"bias_nm": 15.0}}))
    np.testing.assert_allclose(result.signals["hinge_moment_nm"], base.signals["hinge_moment_nm"] + 15.0, atol=1e-9)
    np.testing.assert_array_equal(result.signals["position_deg"], base.signals["position_deg"])


def test_viscous_adds_coefficient_times_speed(base):
    result = run(EffectSet({"viscous": {"coefficient_nms": 2e-4}}))
    speed = result.signals["motor_speed_radps"][0, STEADY]
    extra = result.loss_torque_nm[0, STEADY] - base.loss_torque_nm[0, STEADY]
    np.testing.assert_allclose(extra, 2e-4 * speed, rtol=0.02)


def test_stribeck_adds_friction_that_fades_with_speed(base):
    result = run(EffectSet({"stribeck": {"amplitude_nm": 0.03, "speed_radps": 50.0}}))
    speed = result.signals["motor_speed_radps"][0, STEADY]
    extra = result.loss_torque_nm[0, STEADY] - base.loss_torque_nm[0, STEADY]
    np.testing.assert_allclose(extra, 0.03 / (1 + (speed / 50.0) ** 2), rtol=0.05)


def test_position_friction_grows_with_deflection(base):
    result = run(EffectSet({"position_friction": {"amplitude_nm": 0.02}}))
    position_rad = np.radians(result.signals["position_deg"][0, STEADY])
    extra = result.loss_torque_nm[0, STEADY] - base.loss_torque_nm[0, STEADY]
    np.testing.assert_allclose(extra, 0.02 * np.abs(position_rad) / np.radians(30.0), atol=2e-4)


def test_cogging_ripples_with_motor_angle():
    result = run(EffectSet({"cogging": {"amplitude_nm": 0.02, "periods_per_rev": 6.0}}))
    ripple = result.loss_torque_nm[0, STEADY] - result.loss_torque_nm[0, STEADY].mean()
    assert ripple.std() == pytest.approx(0.02 / np.sqrt(2), rel=0.1)  # a sine of amplitude 0.02


@pytest.mark.parametrize("effect", ["torque_constant", "current_sensor_gain"])
def test_current_scale_effects_scale_the_logged_current(base, effect):
    result = run(EffectSet({effect: {"gain": 1.1}}))
    ratio = result.signals["current_a"][0, STEADY].mean() / base.signals["current_a"][0, STEADY].mean()
    # Sliding needs the same torque: a 10 % stronger motor draws 1/1.1 of the current; a sensor
    # reading 10 % high logs 1.1x the (unchanged) true current, whatever the loop then does.
    expected = 1 / 1.1 if effect == "torque_constant" else 1.1
    assert ratio == pytest.approx(expected, rel=0.01)


def test_a_current_sensor_offset_shifts_the_log_and_not_the_torque_that_slides(base):
    """Sliding needs the same true current, which the loop reaches through the sensor: the log reads it plus
    the offset, and the motion is the same within the loop's own chatter."""
    result = run(EffectSet({"current_sensor_offset": {"offset_a": 0.4}}))
    shift = result.signals["current_a"][0, STEADY] - base.signals["current_a"][0, STEADY]
    assert shift.mean() == pytest.approx(0.4, abs=0.01)
    np.testing.assert_allclose(result.loss_torque_nm[0, STEADY], base.loss_torque_nm[0, STEADY], atol=2e-3)


def test_a_current_sensor_offset_is_held_by_a_stuck_shaft():
    """At rest on its command, unloaded, the loop holds the *measured* current near zero: the true current
    is −offset, and the stuck shaft's friction holds exactly that torque, k_T·offset."""
    still = ramp_knots(0.0, 0.0, 2000)
    offset = 0.5
    result = simulate_batch(
        still,
        NOMINAL,
        GroundLoad(0.0),
        effects=EffectSet({"current_sensor_offset": {"offset_a": offset}}),
        drive=THESIS.params,
    )
    late = slice(1000, 2000)
    assert abs(result.signals["current_a"][0, late].mean()) < 0.02  # the loop's view
    assert np.abs(result.signals["motor_speed_radps"][0, late]).max() == 0.0  # never slips: k_T·0.5 < FSJ
    torque = THESIS.params.torque_constant_nm_per_a * offset
    assert np.abs(result.loss_torque_nm[0, late]).mean() == pytest.approx(torque, rel=0.02)


def test_backlash_delays_the_elevator_at_a_reversal():
    knots = np.concatenate([ramp_knots(0.0, 10.0, 1500), ramp_knots(1.5, -10.0, 1500)[1:]])
    base = simulate_batch(knots, NOMINAL, LOAD, drive=THESIS.params)
    wide = simulate_batch(
        knots, NOMINAL, LOAD, effects=EffectSet({"backlash": {"extra_rad": 0.01}}), drive=THESIS.params
    )
    lag = np.abs(wide.signals["position_deg"][0] - base.signals["position_deg"][0]).max()
    assert lag > np.degrees(0.01) / 4


def test_unknown_effects_and_parameters_are_named():
    with pytest.raises(InputError, match="unknown effect 'friction'"):
        EffectSet({"friction": {}})
    with pytest.raises(InputError) as error:
        EffectSet({"cogging": {"amplitude": 0.1}})
    assert error.value.field == "effects.cogging"
    with pytest.raises(InputError) as error:
        EffectSet({"viscous": {"coefficient_nms": 1.0}})
    assert error.value.field == "effects.viscous.coefficient_nms"


@pytest.mark.parametrize(
    ("variable", "start", "step", "values"),
    [("position", 0.0, np.radians(0.5), (0.0, 0.01, 0.03, 0.01, 0.0)), ("time", 0.0, 0.1, (0.0, 0.02, 0.04, 0.06))],
)
def test_a_friction_table_adds_its_interpolated_value(base, variable, start, step, values):
    table = FrictionTable(variable, start, step, values)
    result = run(EffectSet().with_table(table))
    if variable == "position":
        x = np.radians(result.signals["position_deg"][0, STEADY])
    else:
        x = (np.arange(3000)[STEADY] + 0.5) * 1e-4
    expected = np.interp(x, start + step * np.arange(len(values)), values)
    extra = result.loss_torque_nm[0, STEADY] - base.loss_torque_nm[0, STEADY]
    np.testing.assert_allclose(extra, expected, atol=3e-4)


def test_a_bad_table_is_named():
    with pytest.raises(InputError, match=r"table\.variable"):
        FrictionTable("load", 0.0, 1.0, (0.0, 0.1))
    with pytest.raises(InputError, match=r"table\.values_nm"):
        FrictionTable("time", 0.0, 1.0, (0.0, 2.0))
