"""Every command the README shows, run as it is written, in order, on the bundled examples: the set-up's first
command (past its install), the sample outputs' commands, and the five steps from a service to the operator's
view (the service started on its default port, as the README starts it)."""

import contextlib
import re
import shlex
import socket
import subprocess
import time
from pathlib import Path

import httpx
import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"```(bash|text)\n(.*?)```", re.S)
DEFAULT_URL = "http://127.0.0.1:8000"


def readme_commands() -> list[str]:
    """The README's `ema` commands in order: bash lines (after an install's `&&`), and `$ ` lines of sample output,
    each with its continuation lines joined and its comment dropped."""
    found = []
    for kind, body in BLOCK.findall((ROOT / "README.md").read_text()):
        for line in re.sub(r"\\\n\s*", " ", body).splitlines():
            if kind == "text" and not line.startswith("$ "):
                continue  # a sample output's own lines
            for part in line.removeprefix("$ ").split("&&"):
                command = " ".join(part.split("  #")[0].split())
                if command.startswith("ema "):
                    found.append(command)
    return found


def _port_free() -> bool:
    with contextlib.closing(socket.socket()) as probe:
        return probe.connect_ex(("127.0.0.1", 8000)) != 0


def test_the_readme_shows_the_commands_it_should():
    commands = readme_commands()
    assert commands[0] == "ema estimate examples/window.json"
    assert any(c.startswith("ema calibrate examples/emps/") for c in commands)
    assert "ema serve &" in commands and any(c.startswith("ema history") for c in commands)


@pytest.mark.skipif(not _port_free(), reason="port 8000, the README's service port, is taken on this machine")
def test_every_readme_command_runs_as_written(tmp_path):
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    server = None
    try:
        for command in readme_commands():
            if command == "ema serve &":
                database = tmp_path / "history.sqlite3"
                server = subprocess.Popen([*shlex.split(command[:-2]), "--database", str(database)], cwd=tmp_path)
                _wait_warm(server)
                continue
            done = subprocess.run(["bash", "-c", command], cwd=tmp_path, capture_output=True, text=True, timeout=600)
            assert done.returncode == 0, f"{command}\n{done.stderr[-2000:]}"
        listed = httpx.get(f"{DEFAULT_URL}/v1/actuators", timeout=30).json()  # step 4, as curl would
        assert "tail-7/elevator-left" in {line["actuator_id"] for line in listed}
        assert httpx.get(f"{DEFAULT_URL}/ui", timeout=30).status_code == 200  # step 5, as a browser would
    finally:
        if server is not None:
            server.terminate()
            server.wait(timeout=30)


def _wait_warm(server: subprocess.Popen) -> None:
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline and server.poll() is None:
        with contextlib.suppress(httpx.HTTPError):
            if httpx.get(f"{DEFAULT_URL}/healthz", timeout=2).json().get("warm"):
                return
        time.sleep(0.3)
    raise AssertionError("ema serve did not come up")
