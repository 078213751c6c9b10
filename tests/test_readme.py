"""Every command the README shows, run as it is written, in order within each group of commands that share files,
on the bundled examples: the set-up's first command (past its install), the sample outputs' commands, and the five
steps from a service to the operator's view (the service started on its default port, as the README starts it)."""

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


def readme_samples() -> dict[str, str]:
    """Each sample output the README shows, by its command (as ``readme_commands`` spells it): the lines under its
    ``$ `` line up to the next one."""
    samples: dict[str, str] = {}
    for kind, body in BLOCK.findall((ROOT / "README.md").read_text()):
        if kind != "text":
            continue
        for part in re.split(r"^\$ ", re.sub(r"\\\n\s*", " ", body), flags=re.M)[1:]:
            command, _, shown = part.partition("\n")
            samples[" ".join(command.split())] = shown
    return samples


def sample_pattern(shown: str) -> re.Pattern[str]:
    """What a sample promises, digit for digit: its text with any run of spaces or line breaks matching any other
    (the README wraps long lines), ``...`` and ``(...)`` standing for what it leaves out, and a time line's seconds
    for any (they are this machine's, that day's)."""
    lines = shown.strip().splitlines()
    timed = "\n".join(re.sub(r"\d+\.\d+(?= s\b)", "\0", line) if line.startswith("time:") else line for line in lines)
    pattern = ""
    for part in re.split(r"(\(\.\.\.\)|\.\.\.)", timed):
        if part in ("...", "(...)"):
            pattern += ".*?"
            continue
        words = (re.escape(word).replace("\0", r"[\d.]+") for word in part.split())
        pattern += r"\s+".join(words)
        pattern += r"\s+" if part[-1:].isspace() else ""
    return re.compile(pattern, re.S)


def test_a_sample_is_matched_digit_for_digit():
    shown = "parameter   value\nFDJ   0.05515\n...\ntime: prepare 0.41 s  total 0.54 s"
    pattern = sample_pattern(shown)
    assert pattern.search("parameter value\nFDJ 0.05515\nnote x\ntime: prepare 1.20 s  total 3.00 s")
    assert not pattern.search("parameter value\nFDJ 0.05516\nnote x\ntime: prepare 1.20 s  total 3.00 s")


def _port_free() -> bool:
    with contextlib.closing(socket.socket()) as probe:
        return probe.connect_ex(("127.0.0.1", 8000)) != 0


def test_the_readme_shows_the_commands_it_should():
    commands = readme_commands()
    assert commands[0] == "ema estimate examples/window.json"
    assert any(c.startswith("ema calibrate examples/emps/") for c in commands)
    assert "ema serve &" in commands and any(c.startswith("ema history") for c in commands)


def command_groups() -> dict[str, list[str]]:
    """The README's commands in groups that share no file, each in its order: what each bundled example's commands
    read and write (``rig.json`` is written by the rig's calibration and read by its estimate), and the service's
    steps from ``ema serve &`` on. Run apart, two groups take two cores."""
    groups: dict[str, list[str]] = {"service": []}
    for command in readme_commands():
        if command == "ema serve &" or groups["service"]:
            groups["service"].append(command)
        elif "ballscrew-rig" in command or "rig.json" in command:
            groups.setdefault("rig", []).append(command)
        elif "sts3215" in command:  # runs that lie beside the repository, never in it
            groups.setdefault("sts3215", []).append(command)
        else:
            groups.setdefault(command.split()[2].rpartition("/")[0], []).append(command)
    return groups


def test_every_readme_command_is_in_one_group_in_its_order():
    commands, groups = readme_commands(), command_groups()
    assert sorted(c for group in groups.values() for c in group) == sorted(commands)
    for group in groups.values():
        remaining = iter(commands)
        assert all(command in remaining for command in group)  # a subsequence: the README's order kept
    assert set(groups) == {"examples", "examples/emps", "rig", "service", "sts3215"}


@pytest.mark.skipif(not _port_free(), reason="port 8000, the README's service port, is taken on this machine")
@pytest.mark.parametrize("group", ["examples", "examples/emps", "rig", "service", "sts3215"])
def test_every_readme_command_runs_as_written(tmp_path, group):
    shared = ROOT.parent / "shared" / "data" / "sts3215"
    if group == "sts3215" and not shared.is_dir():
        pytest.skip(f"the STS3215 runs are not beside the repository ({shared}): they are never copied into it")
    work = tmp_path / "work"  # the repository's place: ../shared lies beside it
    work.mkdir()
    (tmp_path / "shared").symlink_to(ROOT.parent / "shared")
    tmp_path = work
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    server, samples = None, readme_samples()
    try:
        for command in command_groups()[group]:
            if command == "ema serve &":
                database = tmp_path / "history.sqlite3"
                server = subprocess.Popen([*shlex.split(command[:-2]), "--database", str(database)], cwd=tmp_path)
                _wait_warm(server)
                continue
            done = subprocess.run(["bash", "-c", command], cwd=tmp_path, capture_output=True, text=True, timeout=600)
            assert done.returncode == 0, f"{command}\n{done.stderr[-2000:]}"
            if command in samples:  # what the README shows it print, digits and notes
                assert sample_pattern(samples[command]).search(done.stdout), f"{command}\n{done.stdout}"
        if server is not None:
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
