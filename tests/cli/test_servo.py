"""The EMPS log through the command line as the README shows it: estimated, calibrated, its document completed,
and its bad files refused naming them."""

import json
from pathlib import Path

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
    assert "windows.0.signals" in capsys.readouterr().err
