import numpy as np
import pytest

from sim.aircraft import GroundLoad
from sim.batch import simulate_batch
from sim.checks import InputError
from sim.noise import NO_NOISE, SensorNoise, add_sensor_noise
from sim.params import HealthParams
from sim.synthetic import synthetic_window
from sim.window import Window
from training.baseline import FrictionLeastSquares


@pytest.mark.parametrize(("noise", "tolerance"), [(NO_NOISE, 0.003), (SensorNoise(), 0.01)])
def test_recovers_fdj_and_eta_o_from_an_in_flight_window(noise, tolerance):
    truth = HealthParams.single(0.1, 0.057, 0.74)
    fitted = FrictionLeastSquares().fit(synthetic_window(truth, seed=9, noise=noise))
    assert fitted.fdj_ == pytest.approx(0.057, rel=tolerance)
    assert fitted.eta_o_ == pytest.approx(0.74, rel=tolerance)
    assert fitted.fsj_ is None  # in flight the shaft never rests: said, not guessed
    assert "break-away" in fitted.fsj_reason_


def test_recovers_fsj_at_a_break_away():
    # On ground with a rising load and the command held, the shaft rests until the load breaks it away.
    for fsj in (0.085, 0.115):
        result = simulate_batch(np.zeros(3001), HealthParams.single(fsj, 0.05, 0.85), GroundLoad(-20.0, -600.0))
        window = Window(result.simulation(0))
        fitted = FrictionLeastSquares(min_speed_radps=0.5, stuck_speed_radps=0.2)
        fitted.fdj_, fitted.eta_o_, fitted.eta_a_ = 0.05, 0.85, float(HealthParams.single().eta_a()[0])
        load = window.signals["hinge_moment_nm"] / 500
        fitted._fit_static(window, load, np.sign(window.signals["motor_speed_radps"]))
        assert fitted.fsj_ == pytest.approx(fsj, rel=0.02)


def test_too_little_motion_is_refused_naming_the_signals():
    result = simulate_batch(np.zeros(1001), HealthParams.single(), GroundLoad(0.0))
    window = Window(add_sensor_noise(result.simulation(0), SensorNoise(), np.random.default_rng(0)))
    with pytest.raises(InputError) as error:
        FrictionLeastSquares().fit(window)
    assert error.value.field == "signals"


def test_settings_are_checked():
    with pytest.raises(InputError, match="min_speed_radps"):
        FrictionLeastSquares(min_speed_radps=-1)
