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


def test_estimate_prints_one_json_document_and_progress_on_stderr(tmp_path, capsys):
    window = tmp_path / "w.json"
    assert main(["simulate", "--out", str(window), "--duration", "0.1", "--fdj", "0.056"]) == EXIT_OK
    capsys.readouterr()
    code = main(["estimate", str(window), "--sims", "40", "--timesteps", "100", "--hidden", "10", "--json"])
    assert code == EXIT_OK
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert result["schema"] == "ema-estimate/1"
    assert result["estimates"]["FDJ"]["value"] > 0
    assert "training" in captured.err


def test_estimate_table_and_bad_inputs(tmp_path, capsys):
    window = tmp_path / "w.json"
    main(["simulate", "--out", str(window), "--duration", "0.1"])
    capsys.readouterr()
    assert main(["estimate", str(window), "--sims", "40", "--timesteps", "100", "--hidden", "10"]) == EXIT_OK
    assert "eta_O" in capsys.readouterr().out
    assert main(["estimate", str(window), "--sims", "5"]) == EXIT_BAD_INPUT
    assert "n_simulations" in capsys.readouterr().err
    (tmp_path / "broken.json").write_text('{"schema": "ema-window/1"}')
    assert main(["estimate", str(tmp_path / "broken.json")]) == EXIT_BAD_INPUT
    assert "flight_condition" in capsys.readouterr().err
    assert main(["estimate", str(tmp_path / "missing.json")]) == EXIT_BAD_INPUT


def test_calibrate_writes_a_figure_and_names_a_bad_truth_file(tmp_path, capsys):
    window, truth = tmp_path / "w.json", tmp_path / "t.json"
    main(["simulate", "--out", str(window), "--duration", "0.15", "--truth-out", str(truth)])
    capsys.readouterr()
    sizes = ["--sims", "40", "--timesteps", "100", "--hidden", "10"]
    figure = tmp_path / "cal.png"
    assert main(["calibrate", str(window), "--truth", str(truth), "--figure", str(figure), "--json", *sizes]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["schema"] == "ema-calibration/1" and figure.stat().st_size > 1000
    (tmp_path / "bad.json").write_text("{}")
    assert main(["calibrate", str(window), "--truth", str(tmp_path / "bad.json"), *sizes]) == EXIT_BAD_INPUT
    assert "bad.json" in capsys.readouterr().err
