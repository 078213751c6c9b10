"""Logged files as they were written: a MATLAB file through its log map, its scale and constants read from the
file; each kind of bad file refused naming it and the variable; limits checked before the work."""

from pathlib import Path

import numpy as np
import pytest
from scipy.io import savemat

from ema.model import log_files
from ema.model.checks import InputError
from ema.model.logmap import logmap_from_dict, read_logmap, read_mapped
from ema.model.window import window_from_dict

EMPS = Path(__file__).resolve().parents[2] / "examples" / "emps"
MAP = read_logmap(EMPS / "log-map.json")
RIG_MAP = EMPS.parent / "ballscrew-rig" / "log-map.json"


def _mat(path: Path, n: int = 300, **changes) -> Path:
    t = np.arange(n) / 1000.0
    columns = {"t": t, "qg": 0.01 * t, "qm": 0.01 * t, "vir": np.ones(n)}
    constants = {"gtau": 35.0, "kp": 160.0, "kv": 243.0}
    variables = {k: v[:, None] for k, v in columns.items()} | {k: np.array([[v]]) for k, v in constants.items()}
    variables |= changes
    savemat(path, {k: v for k, v in variables.items() if v is not None})
    return path


def test_a_matlab_log_becomes_a_servo_window_with_its_constants(tmp_path):
    window = window_from_dict(read_mapped(_mat(tmp_path / "run.mat"), MAP))
    assert window.kind == "servo" and window.sample_rate_hz == pytest.approx(1000.0)
    assert np.allclose(window.signals["drive_force_n"], 35.0)  # vir [V] scaled by the file's gtau [N/V]
    assert window.constants == {
        "drive_gain_n_per_unit": 35.0,
        "position_gain_per_s": 160.0,
        "speed_gain_per_mps": 243.0,
    }
    assert "load_n" not in window.signals  # no load named: no load, not a stuck sensor


@pytest.mark.parametrize(
    ("changes", "named"),
    [({"qm": None}, "'qm'"), ({"qm": np.zeros((299, 1))}, "qm"), ({"gtau": None}, "'gtau'")],
)
def test_a_mapped_variable_missing_or_short_is_named(tmp_path, changes, named):
    with pytest.raises(InputError) as error:
        read_mapped(_mat(tmp_path / "run.mat", **changes), MAP)
    assert named in f"{error.value.field} {error.value.message}" and "run.mat" in error.value.field


def test_a_file_that_is_not_matlab_is_refused_naming_it(tmp_path):
    fake = tmp_path / "fake.mat"
    fake.write_bytes(b"not a MATLAB file at all" * 10)
    with pytest.raises(InputError) as error:
        read_mapped(fake, MAP)
    assert error.value.field == str(fake) and "MATLAB" in error.value.message


def test_a_csv_over_the_row_limit_is_refused_at_its_first_row_past_it(tmp_path, monkeypatch):
    monkeypatch.setattr(log_files, "MAX_ROWS", 1000)
    path = tmp_path / "long.csv"
    path.write_text("a,b\n" + "1,2\n" * 5000)
    with pytest.raises(InputError) as error:
        log_files.read_table(path)
    assert "1,000 rows" in error.value.message


def test_a_file_over_the_size_limit_is_refused_from_its_size(tmp_path, monkeypatch):
    monkeypatch.setattr(log_files, "MAX_LOG_BYTES", 100)
    path = tmp_path / "big.csv"
    path.write_text("a,b\n" + "1,2\n" * 100)
    with pytest.raises(InputError) as error:
        log_files.read_table(path)
    assert "MiB" in error.value.message and error.value.field == str(path)


def test_a_log_map_names_the_role_its_kind_lacks():
    document = MAP.model_dump(by_alias=True) | {"current": {"column": "i", "unit": "A"}}
    with pytest.raises(InputError) as error:
        logmap_from_dict(document)
    assert error.value.field == "current"


@pytest.mark.parametrize(
    ("log_map", "constant", "kind"),
    [(EMPS / "log-map.json", "gear_ratio", "servo"), (RIG_MAP, "position_gain_per_s", "linear")],
)
def test_a_log_map_names_a_constant_its_kinds_log_cannot_record(log_map, constant, kind):
    """Only a servo's log records constants, and only its controller's: another is refused in the map."""
    document = read_logmap(log_map).model_dump(by_alias=True) | {"constants": {constant: "kp"}}
    with pytest.raises(InputError) as error:
        logmap_from_dict(document)
    assert error.value.field == f"constants.{constant}" and kind in error.value.message
