"""Logs as files in ema's own columns: a window of any kind, known by the signals its columns carry."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ema.cli.logs import read_file, read_one
from ema.model.checks import InputError
from ema.model.logmap import read_logmap

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MAPPED = {
    "linear": (EXAMPLES / "ballscrew-rig" / "runs" / "normal_load20_run001.csv", "ballscrew-rig"),
    "servo": (EXAMPLES / "emps" / "DATA_EMPS.mat", "emps"),
}


def _own_csv(window, path: Path, names=None) -> Path:
    """``window`` as a CSV in ema's own columns (``names``: its signals'), in another column order."""
    names = list(reversed(window.signals)) if names is None else names
    head = f"# actuator_id: {window.actuator_id}\n# window_id: own\n# sample_rate_hz: {window.sample_rate_hz}\n"
    rows = np.stack([window.signals[name] for name in names], axis=1)
    path.write_text(head + ",".join(names) + "\n" + "\n".join(",".join(f"{v:.17g}" for v in row) for row in rows))
    return path


@pytest.mark.parametrize("kind", sorted(MAPPED))
def test_a_window_of_any_kind_reads_back_from_its_own_columns_as_csv_and_npz(kind, tmp_path):
    """A real rig's log through its map, written in ema's columns, is the same window read without one."""
    source, folder = MAPPED[kind]
    window = read_one(source, read_logmap(EXAMPLES / folder / "log-map.json"))
    npz = tmp_path / "own.npz"
    np.savez(npz, **window.signals, actuator_id=window.actuator_id, sample_rate_hz=window.sample_rate_hz)
    for path in (_own_csv(window, tmp_path / "own.csv"), npz):
        back = read_file(path)[0]
        assert back.kind == window.kind == kind and back.sample_rate_hz == window.sample_rate_hz
        assert all(np.array_equal(back.signals[name], window.signals[name]) for name in window.signals)


def test_a_file_in_its_own_columns_is_refused_naming_the_log_map_and_each_kinds_signals():
    with pytest.raises(InputError) as refused:
        read_file(MAPPED["linear"][0])
    assert "--log-map" in refused.value.message and "a linear's command_mm, position_mm" in refused.value.message


def test_a_missing_column_is_named_with_its_kind_and_two_kinds_alike_are_refused(tmp_path):
    window = read_one(MAPPED["linear"][0], read_logmap(EXAMPLES / "ballscrew-rig" / "log-map.json"))
    short = _own_csv(window, tmp_path / "short.csv", ["command_mm", "position_mm", "current_a"])
    with pytest.raises(InputError, match=r"lacks the numeric column\(s\) load_n of a linear window"):
        read_file(short)
    both = dict(window.signals)
    both.update({name: window.signals["position_mm"] for name in ("command_deg", "position_deg")})
    both.update({"motor_speed_radps": both["current_a"], "hinge_moment_nm": both["load_n"]})
    mixed = tmp_path / "mixed.npz"
    np.savez(mixed, **both)
    with pytest.raises(InputError, match="rotary and linear window alike"):
        read_file(mixed)


def test_a_slow_log_is_kept_whole_rather_than_cut_into_pieces_no_window_may_be(tmp_path):
    """The rig's 25 Hz run in ema's columns under the default 0.5 s cut: 12-sample pieces would each be refused;
    it stays one window, and says why and which --window-s would cut it."""
    from ema.cli.logs import read_log

    window = read_one(MAPPED["linear"][0], read_logmap(EXAMPLES / "ballscrew-rig" / "log-map.json"))
    folder = tmp_path / "archive"
    folder.mkdir()
    _own_csv(window, folder / "run.csv")
    read = read_log(folder, 0.5)
    assert [w.n_samples for w in read.windows] == [window.n_samples] and read.dropped == {}
    assert "kept whole: 0.5 s at 25 Hz is 12 sample(s)" in read.kept_whole["own"]
    assert "--window-s 4 or more" in read.kept_whole["own"]
    assert [w.n_samples for w in read_log(folder, 4.0).windows] == [100] * (window.n_samples // 100)


def test_a_document_kept_beside_a_log_is_refused_naming_the_flag_that_takes_it(tmp_path):
    """A folder of the examples' shape (a log, its actuator's document and its map): each document is skipped
    saying what it is and which flag takes it, not as a window that fails the window's schema."""
    from ema.cli.logs import read_log

    folder = tmp_path / "archive"
    folder.mkdir()
    for name in ("actuator.json", "log-map.json"):
        (folder / name).write_bytes((EXAMPLES / "ballscrew-rig" / name).read_bytes())
    (folder / "run.csv").write_bytes(MAPPED["linear"][0].read_bytes())
    read = read_log(folder, None, log_map=read_logmap(folder / "log-map.json"))
    assert [w.window_id for w in read.windows] == ["run"]
    assert read.bad_files == {
        str(folder / "actuator.json"): "is an ema-actuator/1 document, not a window: give it with --actuator",
        str(folder / "log-map.json"): "is an ema-logmap/1 document, not a window: give it with --log-map",
    }
    with pytest.raises(InputError, match="ema-actuator/1 document, not a window: give it with --actuator"):
        read_one(folder / "actuator.json")


def _blanked(source: Path, path: Path, column: str, data_row: int) -> Path:
    """``source`` copied to ``path`` with the cell of ``column`` in its ``data_row``-th data row (from 1) empty."""
    lines = source.read_text().splitlines()
    head = next(k for k, line in enumerate(lines) if not line.startswith("#"))
    row = head + data_row
    cells = lines[row].split(",")
    cells[lines[head].split(",").index(column)] = ""
    lines[row] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("mapped", [False, True])
def test_an_empty_cell_is_named_by_its_row_not_taken_for_a_missing_column(mapped, tmp_path):
    """One sample a log lacks: the column and the data row are named, through a log map or in ema's columns."""
    log_map = read_logmap(EXAMPLES / "ballscrew-rig" / "log-map.json")
    source, column = MAPPED["linear"][0], "current"
    if not mapped:
        source, column = _own_csv(read_one(source, log_map), tmp_path / "own.csv"), "current_a"
    path = _blanked(source, tmp_path / "blanked.csv", column, 51)
    with pytest.raises(InputError) as refused:
        read_one(path, log_map) if mapped else read_file(path)
    assert refused.value.field == f"{path}: {column}" and "data row 51 holds no number" in refused.value.message


def test_each_kind_is_cut_as_its_windows_are_read_unless_told(tmp_path):
    """A servo's log (EMPS's first quarter, as a window document) is one window: cut to the thesis's 0.5 s, every
    piece moved one way and was refused. A rotary recording is cut into 0.5 s windows; --window-s cuts either."""
    from ema.cli.logs import read_log
    from ema.kinds.rotary.synthetic import synthetic_window
    from ema.model.params import HealthParams
    from ema.model.window import window_to_dict

    servo = read_one(MAPPED["servo"][0], read_logmap(EXAMPLES / "emps" / "log-map.json"))
    quarter = {name: values[: len(values) // 4] for name, values in servo.signals.items()}
    folder = tmp_path / "archive"
    folder.mkdir()
    (folder / "servo.json").write_text(json.dumps(window_to_dict(replace(servo, signals=quarter, window_id="s"))))
    rotary = synthetic_window(HealthParams.single(), seed=0, duration_s=1.0, actuator_id="r")
    (folder / "rotary.json").write_text(json.dumps(window_to_dict(replace(rotary, window_id="r"))))
    assert sorted(w.window_id for w in read_log(folder, None).windows) == ["r#0", "r#1", "s"]
    assert len(read_log(folder, 1.0).windows) == 1 + 6  # told: the servo's 6.2 s as well
