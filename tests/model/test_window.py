import copy

import numpy as np
import pytest

from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.checks import InputError
from ema.model.params import HealthParams
from ema.model.window import read_window, window_from_dict, window_to_dict, write_window


@pytest.fixture(scope="module")
def document():
    return window_to_dict(synthetic_window(HealthParams.single(), seed=1, duration_s=0.05))


def test_round_trip_through_a_file(tmp_path, document):
    window = window_from_dict(document)
    write_window(window, tmp_path / "w.json")
    again = read_window(tmp_path / "w.json")
    for name, values in window.signals.items():
        np.testing.assert_array_equal(again.signals[name], values)
    assert again.flight_condition == window.flight_condition
    assert not list(tmp_path.glob("*.tmp"))


def test_synthetic_windows_are_seeded(document):
    again = window_to_dict(synthetic_window(HealthParams.single(), seed=1, duration_s=0.05))
    assert again == document


@pytest.mark.parametrize(
    ("duration_s", "rate_hz", "field"),
    [(0.005, 10_000.0, "duration_s"), (20.0, 100_000.0, "duration_s"), (0.5, float("nan"), "sample_rate_hz")],
)
def test_a_synthetic_window_no_window_could_hold_is_refused_naming_the_field(duration_s, rate_hz, field):
    """50 samples, 2 000 000 samples (ema-window/1 holds 100 to 1 000 000), a rate that is no number."""
    with pytest.raises(InputError) as refused:
        synthetic_window(HealthParams.single(), duration_s=duration_s, sample_rate_hz=rate_hz)
    assert refused.value.field == field


def _broken(document, path, value):
    broken = copy.deepcopy(document)
    target = broken
    for key in path[:-1]:
        target = target[key]
    if value is KeyError:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return broken


@pytest.mark.parametrize(
    ("path", "value", "field"),
    [
        (("schema",), "ema-window/2", "schema"),
        (("sample_rate_hz",), 5.0, "sample_rate_hz"),
        (("sample_rate_hz",), "fast", "sample_rate_hz"),
        (("flight_condition", "airspeed_mps"), 400.0, "flight_condition.airspeed_mps"),
        (("flight_condition", "altitude_m"), KeyError, "flight_condition.altitude_m"),
        (("signals", "current_a"), KeyError, "signals.current_a"),
        (("signals", "current_a"), [0.0] * 10, "signals.current_a"),
        (("signals", "position_deg"), [float("nan")] * 500, "signals.position_deg"),
        (("signals", "position_deg"), [90.0] * 500, "signals.position_deg"),
        (("signals", "extra"), [0.0] * 500, "signals.extra"),
        (("signals", "position_mm"), [0.0] * 500, "signals.position_mm"),  # a linear actuator's, in a rotary window
        (("signals", "hinge_moment_nm"), [0.0] * 499 + [1e9], "signals.hinge_moment_nm"),
        (("actuator_id",), 5, "actuator_id"),
        (("constants",), {"position_gain_per_s": 100.0}, "constants.position_gain_per_s"),  # a rotary's: none
    ],
)
def test_bad_windows_name_the_field(document, path, value, field):
    with pytest.raises(InputError) as error:
        window_from_dict(_broken(document, path, value))
    assert error.value.field == field


def test_too_short_and_unreadable(tmp_path, document):
    short = copy.deepcopy(document)
    short["signals"] = {name: values[:50] for name, values in document["signals"].items()}
    with pytest.raises(InputError, match="signals"):
        window_from_dict(short)
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(InputError, match=r"bad\.json"):
        read_window(tmp_path / "bad.json")


def test_a_null_signal_of_another_kind_is_absent_as_in_the_earlier_document(document):
    """The earlier signals document held every kind's signals, null but its own (what a dump of it wrote): such a
    window still reads as its kind's."""
    padded = copy.deepcopy(document)
    padded["signals"].update(command_mm=None, position_mm=None, load_n=None, set_point_m=None)
    assert window_from_dict(padded).signals.keys() == window_from_dict(document).signals.keys()


def test_a_window_is_its_kinds_class_told_once_by_its_signals():
    """``Window(...)`` is its kind's class, kept through a copy and a pickle (a fleet's workers); a kind's code that
    takes its own class refuses another kind's window naming the signals, and a kind's class another's signals."""
    import dataclasses
    import pickle

    from ema.model.window import GearedWindow, RotaryWindow, ServoWindow, Window, as_window

    n = 4
    servo = Window({"set_point_m": np.zeros(n), "position_m": np.zeros(n), "drive_force_n": np.ones(n)}, 1000.0)
    assert type(servo) is ServoWindow and servo.kind == "servo"
    assert type(dataclasses.replace(servo, window_id="b")) is ServoWindow
    assert type(pickle.loads(pickle.dumps(servo))) is ServoWindow
    assert as_window(servo, ServoWindow) is servo
    with pytest.raises(InputError, match="are a servo actuator's: this reads a rotary") as refused:
        as_window(servo, RotaryWindow)
    assert refused.value.field == "signals"
    with pytest.raises(InputError, match="not a geared actuator's signals"):
        GearedWindow(servo.signals, 1000.0)
    with pytest.raises(InputError, match="no one kind's signals"):
        Window({"speed": np.zeros(n)}, 1000.0)
