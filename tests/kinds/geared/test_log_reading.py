"""A recorder's JSON log of a geared servo read as it was written: its map names the fields, its faults are said."""

import json

import numpy as np
import pytest

from ema.cli.logs import read_one
from ema.kinds.geared.log_reading import prepare_geared
from ema.model.actuator import read_actuator
from ema.model.checks import InputError
from ema.model.logmap import read_logmap
from tests.foreign.geared import Load, Servo, recorder_log
from tests.kinds.geared.documents import calibrated_document

EXAMPLE = "examples/sts3215/log-map.json"


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    path = tmp_path_factory.mktemp("recorder") / "run.json"
    return recorder_log(path, Servo(), Load(0.6, 0.12, 8.0), kind="steps", off_after_s=4.5, seed=4)


def test_the_recorder_json_becomes_a_uniform_window_with_its_constants(logged):
    window = read_one(logged, read_logmap(EXAMPLE))
    entries = json.loads(logged.read_text())["entries"]
    assert window.kind == "geared" and window.sample_rate_hz == 100.0
    assert window.constants == {"position_gain": 8.0, "load_mass_kg": 0.6, "arm_length_m": 0.12}
    assert window.resampled is not None and window.resampled.logged_samples == len(entries)
    register = np.array([e["torque"] for e in entries])
    magnitude = np.where(register >= 10.24, register - 10.24, register) / 10.0
    n = window.n_samples  # the last time stamp, jittered, may fall short of the grid's last point
    assert np.median(np.abs(np.abs(window.signals["duty_ratio"]) - magnitude[:n])) < 0.005  # resampled, not rescaled
    positive = np.array([e["torque"] >= 10.24 for e in entries])[:n]
    assert np.mean(np.sign(window.signals["duty_ratio"][positive]) >= 0) > 0.95  # the bit says the direction
    assert set(np.unique(window.signals["motor_on_flag"])) == {0.0, 1.0}  # a switch stays a switch


def test_each_fault_of_the_log_is_said_never_an_error(logged):
    window = read_one(logged, read_logmap(EXAMPLE))
    prepared = prepare_geared(window, calibrated_document())
    said = {note.code: note.text for note in prepared.notes}
    assert {"glitches_repaired", "resampled", "motor_off", "position_quantized"} <= set(said)
    assert said["glitches_repaired"].startswith("1 sample(s)") and "12 V median" in said["glitches_repaired"]
    assert np.all(np.abs(prepared.run.supply_v - 12.0) < 1e-9)
    assert said["motor_off"].startswith(("1.49 s", "1.50 s"))  # 6 s less 4.5 s off


def test_a_log_without_its_gain_is_refused_naming_the_constant(logged, tmp_path):
    document = json.loads(logged.read_text())
    del document["kp"]
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(document))
    with pytest.raises(InputError, match="kp"):
        read_one(bare, read_logmap(EXAMPLE))


def test_an_uncalibrated_document_is_refused_naming_what_it_lacks(logged):
    window = read_one(logged, read_logmap(EXAMPLE))
    bare = read_actuator("examples/sts3215/actuator.json")
    with pytest.raises(InputError, match=r"torque_constant_nm_per_a.*ema calibrate"):
        prepare_geared(window, bare)
