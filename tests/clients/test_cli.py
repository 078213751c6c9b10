import json

from clients.cli import EXIT_BAD_INPUT, EXIT_OK, main
from sim.window import read_window


def test_simulate_writes_a_valid_window_and_the_truth(tmp_path, capsys):
    out, truth = tmp_path / "w.json", tmp_path / "t.json"
    code = main(
        ["simulate", "--out", str(out), "--fdj", "0.055", "--duration", "0.05", "--truth-out", str(truth), "--json"]
    )
    assert code == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    assert report["truth"]["FDJ"] == 0.055
    window = read_window(out)
    assert window.n_samples == 500
    assert json.loads(truth.read_text())["FDJ"] == 0.055


def test_simulate_with_an_effect_and_a_table(tmp_path, capsys):
    code = main(
        ["simulate", "--out", str(tmp_path / "w.json"), "--duration", "0.05", "--effect", "cogging:amplitude_nm=0.02"]
    )
    assert code == EXIT_OK
    assert "cogging" in capsys.readouterr().out


def test_bad_input_exits_2_naming_the_field(tmp_path, capsys):
    assert main(["simulate", "--out", str(tmp_path / "w.json"), "--altitude", "20000"]) == EXIT_BAD_INPUT
    assert "flight_condition.altitude_m" in capsys.readouterr().err
    assert main(["simulate", "--out", str(tmp_path / "w.json"), "--effect", "cogging:amplitude_nm=x"]) == EXIT_BAD_INPUT
    assert "cogging.amplitude_nm" in capsys.readouterr().err
    assert main(["simulate", "--out", str(tmp_path / "missing" / "w.json"), "--duration", "0.05"]) == EXIT_BAD_INPUT
