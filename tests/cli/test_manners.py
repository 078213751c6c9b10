"""The first hour of a new user: what each command reads, writes and says (the manners probe, in tests)."""

import json
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from ema.cli.main import EXIT_BAD_INPUT, EXIT_OK, main
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.params import HealthParams
from ema.model.window import SIGNALS, window_to_dict
from ema.service.main import create_app
from tests.service.conftest import LOCAL, SMALL, settings_for

SIZES = [
    "--sims",
    str(SMALL.n_simulations),
    "--checks",
    str(SMALL.check_simulations),
    "--timesteps",
    str(SMALL.n_timesteps),
    "--hidden",
    str(SMALL.hidden_units),
]


def test_estimate_reads_a_csv_window_as_replay_does(tmp_path, capsys):
    window = synthetic_window(HealthParams.single(), seed=4, duration_s=0.1, actuator_id="csv/1")
    rows = np.stack([window.signals[name] for name in SIGNALS], axis=1)
    text = "# window_id: csv-window\n# sample_rate_hz: 10000\n" + ",".join(SIGNALS) + "\n"
    (tmp_path / "w.csv").write_text(text + "\n".join(",".join(f"{v:.9g}" for v in row) for row in rows))
    assert main(["estimate", str(tmp_path / "w.csv"), "--json", *SIZES]) == EXIT_OK
    result = json.loads(capsys.readouterr().out)
    assert result["window_id"] == "csv-window" and result["estimates"]["FDJ"]["value"] > 0


def test_a_unit_slip_names_the_file_and_the_field(tmp_path, capsys):
    document = window_to_dict(synthetic_window(HealthParams.single(), seed=3, duration_s=0.3))
    document["sample_rate_hz"] = 1000.0  # logged at 10 kHz
    (tmp_path / "w.json").write_text(json.dumps(document))
    assert main(["estimate", str(tmp_path / "w.json"), *SIZES]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{tmp_path / 'w.json'}: sample_rate_hz" in err and "at 9999" in err and "rate stated 0.1x" in err


def test_bench_writes_nothing_unless_asked(tmp_path, monkeypatch):
    import ema.cli.bench as bench

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(bench, "time_windows", lambda *a, **k: {"p50_s": {}, "p95_s": {}})
    monkeypatch.setattr(bench, "references", lambda: {})
    monkeypatch.setattr(bench, "markdown", lambda *a, **k: "table")
    monkeypatch.setattr(bench, "estimate_thesis_window", lambda *a, **k: None)
    result = bench.run_bench(SMALL, [0.5], repeats=1, under_load=0, out=None, docs=False)
    assert result["json"] is None and list(tmp_path.iterdir()) == []


def test_the_front_page_leads_to_the_view_and_the_actuators_are_listed(tmp_path):
    document = window_to_dict(synthetic_window(HealthParams.single(), seed=3, duration_s=0.1, actuator_id="m/1"))
    with TestClient(create_app(settings_for(tmp_path)), base_url=LOCAL) as client:
        front = client.get("/", follow_redirects=False)
        assert front.status_code in (302, 307) and front.headers["location"] == "/ui"
        assert client.post("/v1/estimate", json=document).status_code == 200
        listed = client.get("/v1/actuators").json()
        assert [line["actuator_id"] for line in listed] == ["m/1"] and listed[0]["windows"] == 1
        assert client.get("/v1/actuators/nope/estimates").status_code == 404
        assert client.get("/v1/actuators/nope/prognosis").status_code == 404


def test_an_unknown_actuator_exits_2(capsys):
    from http.server import BaseHTTPRequestHandler, HTTPServer
    from threading import Thread

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self):  # a service that is up (its /healthz) and stores nothing
            healthy = self.path == "/healthz"
            detail = {"detail": [{"loc": ["path", "actuator_id"], "msg": "nothing stored"}]}
            self.send_response(200 if healthy else 404)
            self.end_headers()
            self.wfile.write(json.dumps({"status": "ok"} if healthy else detail).encode())

        def log_message(self, *args):
            pass

    server = HTTPServer(("127.0.0.1", 0), Handler)
    Thread(target=server.serve_forever, daemon=True).start()
    try:
        assert main(["history", "nope", "--url", f"http://127.0.0.1:{server.server_port}"]) == EXIT_BAD_INPUT
    finally:
        server.shutdown()
    assert "nothing stored" in capsys.readouterr().err


def test_serve_beyond_loopback_without_a_key_names_the_flag(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("EMA_API_KEY", raising=False)
    assert main(["serve", "--host", "0.0.0.0", "--database", str(tmp_path / "h.sqlite3")]) == EXIT_BAD_INPUT
    assert "--api-key-file" in capsys.readouterr().err


def test_simulate_refuses_a_linear_actuator_naming_the_flag(tmp_path, capsys):
    rig = Path(__file__).parents[2] / "examples" / "ballscrew-rig" / "actuator.json"
    assert main(["simulate", "--out", str(tmp_path / "w.json"), "--actuator", str(rig)]) == EXIT_BAD_INPUT
    assert "--actuator" in capsys.readouterr().err and not (tmp_path / "w.json").exists()


def test_simulate_refuses_a_window_too_short_for_its_rate_naming_the_flag(tmp_path, capsys):
    """0.01 s at 1 kHz is 10 samples: a window ema itself would refuse to read is never written."""
    out = tmp_path / "w.json"
    assert main(["simulate", "--out", str(out), "--duration", "0.01", "--rate", "1000"]) == EXIT_BAD_INPUT
    assert "--duration" in capsys.readouterr().err and not out.exists()


@pytest.mark.parametrize("durations", ["0.5,-1", "nan"])
def test_bench_refuses_a_duration_of_no_window_naming_the_flag(durations, capsys):
    """Checked before any window is timed (a window of 0 s once drew its command forever)."""
    assert main(["bench", "--durations", durations, "--repeats", "1"]) == EXIT_BAD_INPUT
    assert f"--durations: {durations.split(',')[-1]} is outside" in capsys.readouterr().err


def test_an_output_folder_that_cannot_be_made_is_refused_naming_the_flag_before_any_work(tmp_path, capsys):
    """bench times its windows for minutes before writing bench.json: a folder it cannot make is said first (a
    file where the folder would go); schemas names --out too, and --check writes no folder."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    assert main(["bench", "--out", str(blocker / "sub"), "--repeats", "1", "--durations", "0.05"]) == EXIT_BAD_INPUT
    assert "--out" in capsys.readouterr().err
    assert main(["schemas", "--out", str(blocker / "sub")]) == EXIT_BAD_INPUT
    assert "--out" in capsys.readouterr().err
    assert main(["schemas", "--check", "--out", str(tmp_path / "none")]) != EXIT_OK and not (tmp_path / "none").exists()


def test_the_readmes_series_step_prints_every_window(tmp_path, capsys):
    out = tmp_path / "degrading"
    command = ["simulate", "--out", str(out), "--series", "3", "--every", "25", "--fdj-end", "0.07"]
    assert main([*command, "--duration", "0.1", "--actuator-id", "tail-7/elevator-left"]) == EXIT_OK
    printed = capsys.readouterr().out
    assert "wrote 3 windows" in printed and "window 2: FDJ 0.0700" in printed and len(list(out.iterdir())) == 3


def test_a_replayed_answer_without_eta_o_is_printed_with_a_dash():
    from ema.cli.commands_remote import _print_replay
    from ema.cli.replay import answered

    row = {"window_id": "rig-1", "FDJ": 0.81, "FDJ_unit": "N·m", "eta_O": None, "eta_A": None, "total_s": 0.01}
    assert answered(row) == "FDJ 0.81  η_O not read"
    _print_replay({"rows": [row], "bad_files": {}, "posted": 1, "answered": 1, "refused": 0, "csv": "r.csv"})


def test_a_malformed_database_address_exits_2_naming_the_flag(tmp_path, capsys):
    address = "postgresql://u:p@host:notaport/db"
    assert main(["serve", "--database", address]) == EXIT_BAD_INPUT
    assert "--database" in capsys.readouterr().err
    assert main(["fleet", str(tmp_path), "--out", str(tmp_path / "r.csv"), "--database", address]) == EXIT_BAD_INPUT
    assert "'--database': host:notaport: the port is not a number" in capsys.readouterr().err


def test_schemas_check_outside_the_repository_checks_the_repositorys(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["schemas", "--check"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["folder"].endswith("docs/schemas") and not list(tmp_path.iterdir())


def test_a_rig_calibration_writes_its_figure(tmp_path, capsys):
    rig = Path(__file__).resolve().parents[2] / "examples" / "ballscrew-rig"
    runs = [str(p) for p in sorted((rig / "runs").glob("normal_load*_run00[1-3].csv"))]
    command = ["calibrate", *runs, "--actuator", str(rig / "actuator.json"), "--log-map", str(rig / "log-map.json")]
    assert main([*command, "--figure", str(tmp_path / "rig.png")]) == EXIT_OK
    assert (tmp_path / "rig.png").stat().st_size > 0 and "figure:" in capsys.readouterr().out


def test_a_second_step_naming_nothing_does_not_contradict_the_first(capsys):
    from ema.cli.printing import print_calibration

    step = {"selected": "current_sensor_offset", "reason": "it explains the windows"}
    report = {
        "noise_floor": None,
        "candidates": [],
        "selection_steps": [step, {"selected": None, "reason": "nothing beyond it"}],
        "unexplained": None,
        "held_out": {"note": "five folds"},
        "estimates_before": {},
        "estimates_after": {},
    }
    print_calibration(report)
    printed = capsys.readouterr().out
    assert "named current_sensor_offset" in printed and "nothing further named" in printed
    assert "\nnothing named" not in printed


def test_an_output_whose_folder_cannot_be_made_is_refused_before_any_work(tmp_path, capsys):
    """A file in the way of the folder: said naming the flag as it is read, not after the calibration's work; a
    folder that is not there yet is made, as a results CSV's is."""
    blocker = tmp_path / "taken"
    blocker.write_text("a file, not a folder")
    window = Path(__file__).parents[2] / "examples" / "calibration-window.json"
    assert main(["calibrate", str(window), "--figure", str(blocker / "f.png")]) == EXIT_BAD_INPUT
    said = capsys.readouterr()
    assert "--figure" in said.err and "its folder cannot be made" in said.err and "ema: " not in said.err
    nested = tmp_path / "new" / "folder" / "w.json"
    assert main(["simulate", "--out", str(nested), "--duration", "0.05"]) == EXIT_OK and nested.exists()
