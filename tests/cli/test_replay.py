"""The replay client against a real uvicorn server on 127.0.0.1, and the history across a kill -9."""

import csv
import json
import signal
import threading
import urllib.request
from dataclasses import replace
from http.server import BaseHTTPRequestHandler, HTTPServer

import numpy as np
import pytest

from ema.cli.logs import read_log
from ema.cli.main import EXIT_BAD_INPUT, EXIT_OK, main
from ema.cli.replay import post_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.checks import InputError
from ema.model.params import HealthParams
from ema.model.window import SIGNALS, window_to_dict
from tests.servers import free_port, start_server

ANSWER = {
    "estimates": {name: {"value": 0.85, "std": 0.01} for name in ("FDJ", "eta_O", "eta_A")} | {"FSJ": None},
    "timings_s": {"simulate": 0.1, "train": 0.1, "predict": 0.1, "total": 0.3},
    "fit_check": {"reproduced": True},
}


@pytest.fixture
def log_folder(tmp_path):
    """A folder with a 0.3 s JSON recording (3 windows), a CSV and an NPZ window."""
    folder = tmp_path / "log"
    folder.mkdir()
    recording = synthetic_window(HealthParams.single(0.1, 0.052, 0.82), seed=1, duration_s=0.3, actuator_id="ac-7")
    (folder / "a_recording.json").write_text(json.dumps({**window_to_dict(recording), "window_id": "flight-1"}))
    short = synthetic_window(HealthParams.single(), seed=2, duration_s=0.1)
    rows = np.stack([short.signals[name] for name in SIGNALS], axis=1)
    header = "# actuator_id: ac-7\n# window_id: csv-1\n# sample_rate_hz: 10000\n# flight_id: f-7\n" + ",".join(SIGNALS)
    header += "\n"
    (folder / "b_window.csv").write_text(header + "\n".join(",".join(f"{v:.9g}" for v in row) for row in rows))
    np.savez(folder / "c_window.npz", **short.signals, actuator_id="ac-7", window_id="npz-1")
    return folder


def test_logs_are_read_and_cut_in_order(log_folder):
    assert [w.window_id for w in read_log(log_folder, 10.0).windows] == ["flight-1", "csv-1", "npz-1"]
    read = read_log(log_folder, 0.1)
    assert [w.window_id for w in read.windows] == ["flight-1#0", "flight-1#1", "flight-1#2", "csv-1", "npz-1"]
    # a recording is one power-on: its pieces share a flight (and its sensors' zero); a CSV names its own
    assert [w.flight_id for w in read.windows] == ["flight-1"] * 3 + ["f-7", None]
    assert read.bad_files == {}


def test_a_bad_file_in_a_folder_is_skipped_and_named_alone_it_is_an_error(log_folder):
    (log_folder / "d_broken.csv").write_text("command_deg,position_deg\n1,2\n")
    read = read_log(log_folder, 0.1)
    assert len(read.windows) == 5 and list(read.bad_files) == [str(log_folder / "d_broken.csv")]
    assert "motor_speed_radps" in read.bad_files[str(log_folder / "d_broken.csv")]
    with pytest.raises(InputError, match=r"d_broken\.csv"):
        read_log(log_folder / "d_broken.csv", 0.1)


def test_replay_end_to_end_resume_and_kill_9(tmp_path, log_folder, capsys):
    port, database, out = free_port(), tmp_path / "history.sqlite3", tmp_path / "estimates.csv"
    url = f"http://127.0.0.1:{port}"
    (log_folder / "d_broken.json").write_text('{"schema": "ema-window/1"')  # skipped and said so
    server = start_server(port, database)
    try:
        assert main(["replay", str(log_folder), "--url", url, "--out", str(out), "--window-s", "0.1"]) == EXIT_OK
        printed = capsys.readouterr()
        assert "flight-1#2" in printed.out and "[5/5]" in printed.err
        assert "skipped" in printed.err and "d_broken.json" in printed.err and "1 unreadable file" in printed.out
        assert len(out.read_text().strip().splitlines()) == 1 + 5
        assert main(["replay", str(log_folder), "--url", url, "--out", str(out), "--window-s", "0.1", "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["posted"] == 0  # resumed: nothing sent twice
        # The window in flight when a client died: stored by the server, missing from the CSV.
        in_flight = synthetic_window(HealthParams.single(), seed=4, duration_s=0.1, actuator_id="ac-7")
        first = post_window(url, in_flight, None)
        lines = out.read_text().splitlines()
        folder = tmp_path / "again"
        folder.mkdir()
        (folder / "w.json").write_text(json.dumps(window_to_dict(in_flight)))
        assert main(["replay", str(folder), "--url", url, "--out", str(out), "--json"]) == 0
        row = json.loads(capsys.readouterr().out)["rows"][0]
        assert row["replay"] is True and len(out.read_text().splitlines()) == len(lines) + 1
        assert first["replay"] is False
    finally:
        server.send_signal(signal.SIGKILL)
        server.wait()
    server = start_server(port, database)
    try:
        with urllib.request.urlopen(f"{url}/v1/actuators/ac-7/estimates", timeout=10) as response:
            history = json.loads(response.read())
    finally:
        server.terminate()
        server.wait(timeout=30)
    assert [h["window_id"] for h in history["estimates"]] == [
        "flight-1#0",
        "flight-1#1",
        "flight-1#2",
        "csv-1",
        "npz-1",
        in_flight.window_id,
    ]


def test_a_rerun_posts_the_refused_windows_again_and_not_the_answered(tmp_path, monkeypatch):
    from ema.cli import replay as replaying

    posted, refuse = [], {"first"}

    def answer(url, window, key):
        posted.append(window.window_id)
        return {"error": "signals: too little motion"} if window.window_id in refuse else ANSWER

    monkeypatch.setattr(replaying, "post_window", answer)
    base = synthetic_window(HealthParams.single(), seed=5, duration_s=0.02)
    windows = [replace(base, window_id=name) for name in ("first", "second")]
    out = tmp_path / "estimates.csv"
    replaying.replay(windows, "http://127.0.0.1:9", out)
    refuse.clear()  # e.g. the operator raised a budget
    replaying.replay(windows, "http://127.0.0.1:9", out)
    assert posted == ["first", "second", "first"]


def test_a_replay_whose_every_window_is_refused_exits_2_and_says_why_in_full(tmp_path, capsys):
    message = "the position's travel is 1.56x the speed's integral through the gear ratio of this actuator"
    detail = json.dumps({"detail": [{"loc": ["body", "signals", "motor_speed_radps"], "msg": message}]}).encode()

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self):  # /healthz: the replay asks first
            self.send_response(200)
            self.end_headers()
            self.wfile.write(b'{"status": "ok"}')

        def do_POST(self):
            self.rfile.read(int(self.headers["content-length"]))
            self.send_response(422)
            self.end_headers()
            self.wfile.write(detail)

        def log_message(self, *args):
            pass

    server = HTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    window = tmp_path / "w.json"
    window.write_text(json.dumps(window_to_dict(synthetic_window(HealthParams.single(), seed=3, duration_s=0.02))))
    try:
        code = main(
            ["replay", str(window), "--url", f"http://127.0.0.1:{server.server_port}", "--out", str(tmp_path / "e.csv")]
        )
    finally:
        server.shutdown()
    captured = capsys.readouterr()
    assert code == EXIT_BAD_INPUT and "none of the 1 window(s)" in captured.err
    assert f"signals.motor_speed_radps: {message}" in captured.out


def test_a_bad_file_exits_2_naming_it(tmp_path, capsys):
    bad = tmp_path / "broken.csv"
    bad.write_text("command_deg,position_deg\n1,2\n")
    assert main(["replay", str(bad), "--url", "http://127.0.0.1:9"]) == EXIT_BAD_INPUT
    assert "broken.csv" in capsys.readouterr().err


def test_post_waits_out_a_503_and_retries_the_same_window():
    answers = [(503, {"Retry-After": "2"}, b"{}"), (200, {}, json.dumps({"ok": True}).encode())]
    seen = []

    class Handler(BaseHTTPRequestHandler):
        def do_POST(self):
            seen.append(json.loads(self.rfile.read(int(self.headers["content-length"])))["window_id"])
            status, headers, body = answers.pop(0)
            self.send_response(status)
            for key, value in headers.items():
                self.send_header(key, value)
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    server = HTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    slept = []
    window = synthetic_window(HealthParams.single(), seed=3, duration_s=0.02)
    try:
        answer = post_window(f"http://127.0.0.1:{server.server_port}", window, None, sleep=slept.append)
    finally:
        server.shutdown()
    assert answer == {"ok": True}
    assert slept == [2.0]
    assert seen == [window.window_id, window.window_id]


def test_a_replay_writes_nothing_in_the_working_folder(tmp_path, capsys, monkeypatch, log_folder):
    """To a service that is not there: said at once, no file anywhere; the answers' CSV goes to the user's state
    folder unless --out names one, and the replay says where."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    assert main(["replay", str(log_folder / "b_window.csv"), "--url", "http://127.0.0.1:9"]) != EXIT_OK
    assert "cannot reach the service" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == [] or not (tmp_path / "state").exists()
    assert not list(tmp_path.glob("*.csv"))


def test_a_service_that_dies_mid_request_is_named_as_such(capsys, log_folder):
    """A server that takes the request and closes the connection: the replay says the service stopped answering,
    not "internal error"."""
    import socket

    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]

    def accept_and_drop() -> None:
        for _ in range(3):
            connection, _ = listener.accept()
            connection.recv(65536)
            connection.close()

    threading.Thread(target=accept_and_drop, daemon=True).start()
    status = main(["replay", str(log_folder / "b_window.csv"), "--url", f"http://127.0.0.1:{port}"])
    listener.close()
    err = capsys.readouterr().err
    assert status != EXIT_OK and "stopped answering" in err and "internal error" not in err


@pytest.mark.parametrize("command", ["replay", "history"])
def test_an_address_that_is_no_services_root_exits_2_naming_the_flag(command, tmp_path, capsys, log_folder):
    """Another web server there, or the service's address with /v1 added (404 at /healthz): no file written and
    no actuator blamed; an address with no scheme is refused as the flag is read."""

    class NotFound(BaseHTTPRequestHandler):
        def do_GET(self):
            self.send_response(404)
            self.end_headers()

        def log_message(self, *args):
            pass

    server = HTTPServer(("127.0.0.1", 0), NotFound)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    out = tmp_path / "answers.csv"
    target = [str(log_folder / "b_window.csv"), "--out", str(out)] if command == "replay" else ["tail-1"]
    try:
        assert main([command, *target, "--url", f"http://127.0.0.1:{server.server_port}/v1"]) == EXIT_BAD_INPUT
    finally:
        server.shutdown()
    said = capsys.readouterr().err
    assert "--url" in said and "HTTP 404" in said and "ACTUATOR_ID" not in said and not out.exists()
    assert main([command, *target, "--url", "127.0.0.1:8000"]) == EXIT_BAD_INPUT
    assert "--url" in capsys.readouterr().err


def test_a_servo_log_is_refused_until_its_document_is_stored_then_stored_once(tmp_path, capsys):
    """The EMPS log (a servo's) into a service that holds no document for it: refused, saying how to store one;
    ``--actuator`` stores it before posting (the key asked for and named), and a rerun adds no version. Its
    history has no trend yet (no level): said, and no figure is claimed."""
    from pathlib import Path

    examples = Path(__file__).resolve().parents[2] / "examples" / "emps"
    log = [str(examples / "DATA_EMPS.mat"), "--log-map", str(examples / "log-map.json")]
    port, key = free_port(), tmp_path / "key.txt"
    key.write_text("a-key-of-sixteen-or-more\n")
    (tmp_path / "wrong.txt").write_text("not-the-key-0123456789\n")
    url, out = f"http://127.0.0.1:{port}", str(tmp_path / "answers.csv")
    server = start_server(
        port, tmp_path / "history.sqlite3", EMA_API_KEY="a-key-of-sixteen-or-more", EMA_MAX_WINDOW_S="30"
    )  # the 24.8 s log within its window limit
    try:
        replay = ["replay", *log, "--url", url, "--out", out, "--json"]
        assert main(replay) == EXIT_BAD_INPUT  # no key: the first post names the flag
        assert "--api-key-file" in capsys.readouterr().err
        assert main([*replay, "--api-key-file", str(key)]) == EXIT_BAD_INPUT  # nothing answered
        assert "PUT its document to /v1/actuators/emps/axis" in capsys.readouterr().out
        stored = [*replay, "--actuator", str(examples / "actuator.json")]
        assert main([*stored, "--api-key-file", str(tmp_path / "wrong.txt")]) == EXIT_BAD_INPUT
        assert "--api-key-file" in capsys.readouterr().err
        for _ in range(2):
            assert main([*stored, "--api-key-file", str(key)]) == EXIT_OK
            captured = capsys.readouterr()
            assert "emps/axis: its document stored in the service (version 1)" in captured.err
        assert json.loads(captured.out)["posted"] == 0  # the rerun resumed: answered the first time
        rows = list(csv.DictReader(Path(out).read_text().splitlines()))
        assert [bool(row["error"]) for row in rows] == [True, False] and float(rows[-1]["FDJ"]) > 0
        plot = tmp_path / "fdj.png"  # no nominal, no threshold yet: no trend, so no figure, and said
        history = ["history", "emps/axis", "--url", url, "--api-key-file", str(key), "--plot", str(plot)]
        assert main(history) == EXIT_OK and not plot.exists()
        captured = capsys.readouterr()
        assert "no figure written" in captured.err and "[no_threshold]" in captured.out
        assert main([*history, "--parameter", "stiffness"]) == EXIT_BAD_INPUT  # not one of the servo's: named
        refused = capsys.readouterr().err
        assert "--parameter: 'stiffness' is not one of this actuator's" in refused and "mass_kg" in refused
        assert main([*history, "--parameter", "mass_kg"]) == EXIT_OK  # its own constant: one window, no trend yet
        assert "no figure written" in capsys.readouterr().err and not plot.exists()
        assert main(history[:4]) == EXIT_BAD_INPUT and "--api-key-file" in capsys.readouterr().err
    finally:
        server.terminate()
        server.wait(timeout=30)
