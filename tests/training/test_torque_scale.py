"""The motor's torque per logged current read per window, on foreign windows (tests/foreign's own k_T and
current sensor gain, fed back through its loop)."""

import pytest

from sim.window import window_from_dict
from tests.foreign.windows import Effects, draw
from training.conditioning import prepare
from training.torque_scale import TorqueScale

FAMILIES = ("thesis", "cruise", "gust", "doublet", "steps")


def _read(seed: int, effects: Effects) -> TorqueScale:
    drawn = draw(seed, FAMILIES[seed % 5], effects=effects)
    return prepare(window_from_dict(drawn.document)).scale


@pytest.mark.parametrize("gain", [0.96, 1.02, 1.05])
def test_a_warm_or_cold_motors_torque_constant_is_read_within_its_std(gain):
    """k_T·gain at the shaft: the current reads gain⁻¹ of what the spec's k_T needs (above 1, the motor's
    peak torque cuts the saturated samples, where nothing is scaled)."""
    for seed in range(60, 65):
        read = _read(seed, Effects(torque_constant_gain=gain))
        assert read.factor == pytest.approx(gain, abs=max(3 * read.gain_std, 0.001)), seed
        assert read.spread["FDJ"] > 0.0


@pytest.mark.parametrize("gain", [0.97, 1.03])
def test_a_current_sensors_gain_is_read_as_the_inverse_scale(gain):
    for seed in range(65, 70):
        read = _read(seed, Effects(current_sensor_gain=gain))
        assert read.factor == pytest.approx(1 / gain, abs=max(3 * read.gain_std, 0.001)), seed


def test_the_specs_torque_constant_is_left_alone():
    """On 420 clean foreign windows of every benchmark group the likelihood-ratio z stayed under 2.6 (MIN_Z 4);
    nor do a sensor off zero or a viscous coefficient 1.2–2x the spec's pass for a scale."""
    assert all(_read(seed, Effects()) == TorqueScale() for seed in range(70, 80))
    assert _read(80, Effects(hinge_bias_nm=8.0)) == TorqueScale()
    assert _read(81, Effects(current_bias_a=-0.2)) == TorqueScale()
    assert _read(82, Effects(viscous_factor=1.8)) == TorqueScale()
