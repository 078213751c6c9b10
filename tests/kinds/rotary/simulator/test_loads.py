import numpy as np
import pytest

from ema.kinds.rotary.simulator.loads import (
    A_DEFAULT,
    B_DEFAULT,
    GroundLoad,
    discretize,
    expm,
    flight_load_model,
    state_space,
    trim,
)
from ema.model.aircraft import FlightCondition, HingeGeometry
from ema.model.checks import InputError


def test_default_eigenvalues_match_the_spec():
    a, _ = state_space(FlightCondition())
    eigenvalues = np.sort_complex(np.linalg.eigvals(a))
    expected = np.sort_complex(np.array([-1.912, 0.0976, -0.151 + 0.115j, -0.151 - 0.115j]))
    np.testing.assert_allclose(eigenvalues, expected, atol=2e-3)


def test_default_condition_reproduces_the_tabulated_model_and_trim():
    a, b = state_space(FlightCondition())
    np.testing.assert_allclose(a, A_DEFAULT, rtol=1e-12)
    np.testing.assert_allclose(b, B_DEFAULT, rtol=1e-12)
    alpha, delta = trim(FlightCondition())
    assert alpha == pytest.approx(0.03691, rel=1e-6)
    assert delta == pytest.approx(-0.013244, rel=1e-6)


def test_pitch_stiffness_scales_with_dynamic_pressure():
    slow, fast = state_space(FlightCondition(100.0, 0.0))[0], state_space(FlightCondition(200.0, 0.0))[0]
    assert fast[3, 1] / slow[3, 1] == pytest.approx(4.0)
    high = state_space(FlightCondition(200.0, 8000.0))[0]
    assert abs(high[3, 1]) < abs(fast[3, 1])  # thinner air, weaker aerodynamics


def test_expm_matches_the_eigendecomposition():
    values, vectors = np.linalg.eig(A_DEFAULT)
    expected = (vectors @ np.diag(np.exp(values * 0.7)) @ np.linalg.inv(vectors)).real
    np.testing.assert_allclose(expm(A_DEFAULT * 0.7), expected, atol=1e-12)


def test_discretization_is_exact_for_a_held_input():
    dt = 1e-3
    ad, bd = discretize(A_DEFAULT, B_DEFAULT, dt)
    x, h = np.array([1.0, 0.02, 0.01, -0.03]), dt / 100

    def rate(state):
        return A_DEFAULT @ state + B_DEFAULT * 0.01

    exact = ad @ x + bd * 0.01
    for _ in range(100):  # classical RK4 over the same interval, u = 0.01 rad held
        k1 = rate(x)
        k2 = rate(x + h / 2 * k1)
        k3 = rate(x + h / 2 * k2)
        k4 = rate(x + h * k3)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    np.testing.assert_allclose(exact, x, rtol=1e-10, atol=1e-14)


def test_a_25_degree_deflection_loads_the_hinge_with_about_290_nm():
    load = flight_load_model(FlightCondition(), 1e-4)
    delta = np.radians(25.0)
    static = load.hinge_delta_nm * delta  # the δ term alone, before α responds
    assert 250.0 <= abs(static) <= 300.0
    assert static < 0  # restoring: opposite to the deflection
    # Held for a quarter second the aircraft pitches and α_t unloads the surface to ≈ 260 N·m
    # (held longer, α_t reaches its ±15° validity limit).
    x = np.zeros(4)
    for _ in range(2_500):
        x = load.ad @ x + load.bd * (delta - load.trim_elevator_rad)
    alpha_t = np.clip(load.alpha_t0_rad + load.alpha_t_row @ x, -load.alpha_t_limit_rad, load.alpha_t_limit_rad)
    total = load.hinge_bias_nm + load.hinge_alpha_nm * alpha_t + static
    assert 240.0 <= abs(total) < abs(static)


def test_hinge_moment_scales_with_dynamic_pressure():
    geometry = HingeGeometry()
    for condition in (FlightCondition(90.0, 0.0), FlightCondition(215.0, 10_000.0)):
        load = flight_load_model(condition, 1e-4)
        expected = condition.dynamic_pressure_pa * geometry.area_m2 * geometry.chord_m * geometry.ch_delta_per_rad
        assert load.hinge_delta_nm == pytest.approx(expected)
        assert geometry.per_deflection_nm_per_rad(condition) == pytest.approx(expected)
    # the aircraft's default: q̄0 ≈ 14 340 Pa, so 25° of deflection alone gives ≈ 290 N·m
    per_rad = HingeGeometry().per_deflection_nm_per_rad(FlightCondition())
    assert per_rad * np.radians(25.0) == pytest.approx(-292.5, abs=1)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"airspeed_mps": 80.0}, "flight_condition.airspeed_mps"),
        ({"airspeed_mps": float("nan")}, "flight_condition.airspeed_mps"),
        ({"altitude_m": 12_000.0}, "flight_condition.altitude_m"),
    ],
)
def test_outside_the_envelope_names_the_field(kwargs, field):
    with pytest.raises(InputError) as error:
        FlightCondition(**kwargs)
    assert error.value.field == field


def test_ground_load_is_checked():
    with pytest.raises(InputError, match=r"ground_load\.constant_nm"):
        GroundLoad(constant_nm=1e4)
