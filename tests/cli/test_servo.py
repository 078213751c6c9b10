"""The EMPS log through the command line as the README shows it: estimated, calibrated, its document completed,
and its bad files refused naming them."""

import json
from pathlib import Path

import pytest

from ema.cli.main import EXIT_BAD_INPUT, EXIT_OK, main

EMPS = Path(__file__).resolve().parents[2] / "examples" / "emps"
READ = ["--actuator", str(EMPS / "actuator.json"), "--log-map", str(EMPS / "log-map.json")]


def test_the_emps_log_is_estimated_and_calibrated_as_the_readme_shows(tmp_path, capsys):
    assert main(["estimate", str(EMPS / "DATA_EMPS.mat"), *READ]) == EXIT_OK
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines() if line}
    assert rows["FDJ"].endswith(" N") and rows["mass_kg"].endswith(" kg")
    completed = tmp_path / "emps.json"
    command = ["calibrate", str(EMPS / "DATA_EMPS.mat"), *READ, "--out-actuator", str(completed)]
    assert main([*command, "--figure", str(tmp_path / "f.png"), "--json"]) == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    assert report["selected_effects"][0] == "viscous_down" and (tmp_path / "f.png").stat().st_size > 0
    assert json.loads(completed.read_text())["servo"]["mass_kg"] > 0
    assert main(["estimate", str(EMPS / "DATA_EMPS.mat"), "--actuator", str(completed), *READ[2:], "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["estimates"]["FDJ"]["nominal"] > 0


def test_a_matlab_file_without_a_map_and_a_map_without_its_variable_exit_2(tmp_path, capsys):
    assert main(["estimate", str(EMPS / "DATA_EMPS.mat")]) == EXIT_BAD_INPUT
    assert "--log-map" in capsys.readouterr().err
    broken = json.loads((EMPS / "log-map.json").read_text()) | {"set_point": {"column": "qref", "unit": "m"}}
    (tmp_path / "map.json").write_text(json.dumps(broken))
    command = ["estimate", str(EMPS / "DATA_EMPS.mat"), "--actuator", str(EMPS / "actuator.json")]
    assert main([*command, "--log-map", str(tmp_path / "map.json")]) == EXIT_BAD_INPUT
    assert "'qref'" in capsys.readouterr().err


def test_a_rig_run_calibrated_without_its_actuator_exits_2_naming_the_signals(capsys):
    rig = Path(__file__).resolve().parents[2] / "examples" / "ballscrew-rig"
    run = rig / "runs" / "normal_load20_run001.csv"
    assert main(["calibrate", str(run), "--log-map", str(rig / "log-map.json")]) == EXIT_BAD_INPUT
    assert "--actuator" in capsys.readouterr().err


def _broken_files(folder: Path) -> list[Path]:
    """An empty file of every format, and a MATLAB and an NPZ file cut short (a copy interrupted)."""
    folder.mkdir()
    paths = [folder / name for name in ("empty.mat", "empty.csv", "empty.json", "empty.npz")]
    for path in paths:
        path.write_bytes(b"")
    cut_mat, cut_npz = folder / "cut.mat", folder / "cut.npz"
    cut_mat.write_bytes((EMPS / "DATA_EMPS.mat").read_bytes()[:4096])
    import io

    import numpy as np

    buffer = io.BytesIO()
    np.savez(buffer, t=np.arange(1000.0))
    cut_npz.write_bytes(buffer.getvalue()[:300])
    return [*paths, cut_mat, cut_npz]


def test_an_empty_or_cut_file_of_any_format_exits_2_naming_it(tmp_path, capsys):
    for path in _broken_files(tmp_path / "broken"):
        for flags in ([], READ):
            assert main(["estimate", str(path), *flags]) == EXIT_BAD_INPUT, path
            err = capsys.readouterr().err
            assert "bad input: " in err and str(path) in err and "internal error" not in err, err


def test_a_folder_with_empty_and_cut_files_skips_each_naming_it_and_answers_the_rest(tmp_path, capsys):
    broken = _broken_files(tmp_path / "archive")
    (tmp_path / "archive" / "window.json").write_bytes((EMPS.parent / "window.json").read_bytes())
    out = tmp_path / "rows.csv"
    assert main(["fleet", str(tmp_path / "archive"), "--out", str(out), "--workers", "1", "--sims", "16"]) == EXIT_OK
    said = capsys.readouterr()
    assert all(f"skipped {path}" in said.err for path in broken), said.err
    assert "1 answered" in said.out + said.err and len(out.read_text().splitlines()) == 2


def test_a_figure_without_the_plots_extra_is_refused_before_the_work(tmp_path, capsys, monkeypatch):
    import importlib.util

    from ema import kinds

    found = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "matplotlib" else found(name, *a))
    monkeypatch.setattr(kinds, "calibrate", lambda *a, **k: pytest.fail("calibrated before the flags were checked"))
    command = ["calibrate", str(EMPS / "DATA_EMPS.mat"), *READ, "--figure", str(tmp_path / "f.png")]
    assert main(command) == EXIT_BAD_INPUT
    assert "--figure" in (err := capsys.readouterr().err) and "pip install 'ema[plots]'" in err, err
    assert not (tmp_path / "f.png").exists()


def test_a_figure_that_cannot_be_drawn_still_prints_the_report(tmp_path, capsys, monkeypatch):
    from ema.cli import figures

    def broken(plot, path):
        raise OSError("disk full")

    monkeypatch.setattr(figures, "residual_figure", broken)
    command = ["calibrate", str(EMPS / "DATA_EMPS.mat"), *READ, "--figure", str(tmp_path / "f.png"), "--json"]
    assert main(command) == EXIT_BAD_INPUT
    said = capsys.readouterr()
    assert json.loads(said.out)["selected_effects"] and "--figure" in said.err and "the report stands" in said.err
