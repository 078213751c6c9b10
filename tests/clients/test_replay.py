"""The replay client against a real uvicorn server on 127.0.0.1, and the history across a kill -9."""

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from http.server import BaseHTTPRequestHandler, HTTPServer

import numpy as np
import pytest

from clients.cli import EXIT_BAD_INPUT, EXIT_OK, main
from clients.logs import read_log
from clients.replay import post_window
from sim.params import HealthParams
from sim.synthetic import synthetic_window
from sim.window import SIGNALS, window_to_dict

SMALL_ENV = {
    "EMA_PIPELINE__N_SIMULATIONS": "16",
    "EMA_PIPELINE__CHECK_WINDOWS": "8",
    "EMA_PIPELINE__N_TIMESTEPS": "50",
    "EMA_PIPELINE__HIDDEN_UNITS": "8",
}


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _start_server(port: int, database) -> subprocess.Popen:
    env = {**os.environ, **SMALL_ENV}
    command = [sys.executable, "-m", "clients.cli", "serve", "--port", str(port), "--database", str(database)]
    server = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/healthz", timeout=2) as response:
                if json.loads(response.read())["warm"]:
                    return server
        except OSError:
            time.sleep(0.3)
    server.kill()
    raise RuntimeError("the server did not become warm in 180 s")


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
    windows = read_log(log_folder)
    assert [w.window_id for w in windows] == ["flight-1", "csv-1", "npz-1"]
    from clients.logs import windows_of

    ids = [w.window_id for w, _ in windows_of(log_folder, 0.1)]
    assert ids == ["flight-1#0", "flight-1#1", "flight-1#2", "csv-1", "npz-1"]
    # a recording is one power-on: its pieces share a flight (and its sensors' zero); a CSV names its own
    assert [w.flight_id for w, _ in windows_of(log_folder, 0.1)] == ["flight-1"] * 3 + ["f-7", None]


def test_replay_end_to_end_resume_and_kill_9(tmp_path, log_folder, capsys):
    port, database, out = _free_port(), tmp_path / "history.sqlite3", tmp_path / "estimates.csv"
    url = f"http://127.0.0.1:{port}"
    server = _start_server(port, database)
    try:
        assert main(["replay", str(log_folder), "--url", url, "--out", str(out), "--window-s", "0.1"]) == EXIT_OK
        printed = capsys.readouterr()
        assert "flight-1#2" in printed.out and "[5/5]" in printed.err
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
    server = _start_server(port, database)
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
        "synthetic-seed4",
    ]


def test_a_refused_window_is_not_posted_again_on_a_rerun(tmp_path, monkeypatch):
    from clients import replay as replaying

    posted = []
    monkeypatch.setattr(replaying, "post_window", lambda url, w, key: posted.append(w.window_id) or {"error": "422"})
    window = synthetic_window(HealthParams.single(), seed=5, duration_s=0.02)
    out = tmp_path / "estimates.csv"
    replaying.replay([window], "http://127.0.0.1:9", out)
    replaying.replay([window], "http://127.0.0.1:9", out)
    assert posted == [window.window_id]


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
