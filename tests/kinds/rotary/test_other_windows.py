"""What other windows of an actuator read, gathered: closed forms of the combination, and the flight rule."""

import numpy as np
import pytest

from ema.estimate.documents.window_facts import HistoryReadings, InertiaReading, SensorZero
from ema.kinds import readings_of_results
from ema.kinds.rotary.inertia import NAMED_WINDOWS, combined_inertia, since_change
from ema.kinds.rotary.other_windows import best_zero, known_from
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from tests.service.conftest import SMALL


def _reading(factor: float, std: float, name: str) -> InertiaReading:
    return InertiaReading(factor=factor, std=std, window_ids=[name])


def test_readings_that_agree_combine_by_their_inverse_variances():
    combined = combined_inertia([_reading(1.05, 0.002, "a"), _reading(1.054, 0.004, "b")])
    weights = np.array([1 / 0.002**2, 1 / 0.004**2])
    assert combined.factor == pytest.approx(np.dot(weights, [1.05, 1.054]) / weights.sum())
    assert combined.std == pytest.approx(1 / np.sqrt(weights.sum()))  # χ² = 0.8 < 1: no wider
    assert combined.window_ids == ["a", "b"]


def test_readings_that_scatter_beyond_their_stds_widen_the_std_by_the_birge_ratio():
    rng = np.random.default_rng(3)
    factors = 1.07 + 0.01 * rng.normal(size=40)  # each says ± 0.001, they scatter by 0.01
    combined = combined_inertia([_reading(float(f), 0.001, f"w{i}") for i, f in enumerate(factors)])
    assert combined.std == pytest.approx(0.01 / np.sqrt(40), rel=0.25)
    assert abs(combined.factor - 1.07) < 3 * combined.std
    assert combined.window_ids == [f"w{i}" for i in range(40 - NAMED_WINDOWS, 40)]
    assert combined_inertia([]) is None


def test_the_zero_is_the_flights_most_precise_and_j_m_the_actuators():
    base = estimate_window(
        synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS
    ).window

    def info(flight_id, zero_std, inertia=None):
        zero = SensorZero(window_id=f"{flight_id}-{zero_std}", hinge_nm=0.0, current_a=0.1, torque_std_nm=zero_std)
        return base.model_copy(update={"flight_id": flight_id, "sensor_zero": zero, "inertia_read": inertia})

    windows = [info("f", 2e-4), info("f", 1e-4), info("g", 1e-6, _reading(1.06, 0.001, "x")), info(None, 1e-7)]
    flight_f = readings_of_results(THESIS, windows, "f")
    assert flight_f.sensor_zero.window_id == "f-0.0001"
    assert flight_f.inertia.factor == 1.06  # J_M from any flight: it stays with the build
    assert readings_of_results(THESIS, windows, None).sensor_zero is None
    assert readings_of_results(THESIS, [], "f") == HistoryReadings()
    assert best_zero([]) is None


def test_history_reaches_conditioning_as_read():
    zero = SensorZero(window_id="z", hinge_nm=2.0, current_a=-0.1, torque_std_nm=3e-4)
    known = known_from(HistoryReadings(sensor_zero=zero, inertia=_reading(1.04, 0.002, "j")))
    assert (known.zero.hinge_nm, known.zero.current_a, known.zero.zero_std_nm) == (2.0, -0.1, 3e-4)
    assert known.zero.carried_from == "z" and not known.zero.read
    assert (known.inertia_factor, known.inertia_std, known.inertia_from) == (1.04, 0.002, ("j",))
    assert known_from(None) == known_from(HistoryReadings())


def test_j_m_is_read_since_it_last_changed_where_two_readings_say_so():
    before = [_reading(1.06, 0.002, f"b{i}") for i in range(5)]
    after = [_reading(1.0, 0.002, f"a{i}") for i in range(3)]
    assert since_change([*before, *after]) == after  # a part replaced: the readings since
    assert combined_inertia([*before, *after]).factor == pytest.approx(1.0)
    alone = [*before, _reading(1.0, 0.002, "a0")]  # one reading against five: replaced, or gone wrong
    assert since_change(alone) == alone and combined_inertia(alone).std > 0.01


def test_a_prognosis_prints_the_actuators_j_m_where_its_windows_read_one():
    from ema.kinds import prognosis_lines

    read = {"inertia": {"factor": 1.06, "std": 0.002, "window_ids": ["w1"]}}
    assert prognosis_lines(read) == ["J_M 1.0600 ± 0.002x the document's, as windows that could tell it read it"]
    assert prognosis_lines({"inertia": None}) == prognosis_lines({"trends": {}}) == []
