"""The real-time benchmark's report: shares of the idle p95 and of both yardstick readings, and the CPU the
service spent; its CPU reading against a process of known work."""

import os
import subprocess
import sys
import time

import numpy as np
import pytest

from benchmarks.real_time import KIND_LIMIT, KINDS, LOADED_LIMIT, Pass, cpu_seconds, documents, report
from tests.foreign.windows import draw


def test_each_row_is_its_p95_over_the_idle_one_and_over_each_yardstick() -> None:
    idle = list(np.linspace(0.1, 0.2, 21))  # p95 0.195, 3.15 s in all
    loaded = [2 * x for x in idle]
    kinds = [KINDS[0]] * 15 + [KINDS[1]] * 6  # the second kind the slowest six: median 0.1875 s
    passes = {
        "idle": [Pass(idle[:10], 2.0, kinds[:10]), Pass(idle[10:], 2.5, kinds[10:])],
        "2 busy processes": [Pass(loaded, 4.41, kinds)],
    }
    text = report(passes, {"one thread": 1.95, "every thread": 0.975, "every thread, loaded": 1.95}, 21)
    rows = [line for line in text.splitlines() if line.startswith(("| idle", "| 2 busy"))]
    assert rows[0] == "| idle | 0.150 | 0.195 | 1.00 | 0.100 | 0.200 | 0.214 | 1.43 |"
    assert rows[1] == "| 2 busy processes | 0.300 | 0.390 | 2.00 | 0.200 | 0.400 | 0.210 | 0.70 |"
    assert f"≤ {LOADED_LIMIT:g}x the idle p95" in text
    assert "busy processes 1.950 s on every thread, 2.00x" in text
    by_kind = [line for line in text.splitlines() if line.startswith(tuple(f"| {k} |" for k in KINDS[:2]))]
    assert by_kind == [f"| {KINDS[1]} | 6 | 1.25x |", f"| {KINDS[0]} | 15 | 0.90x |"]  # slowest first
    assert f"no kind above {KIND_LIMIT:g}x, not met" in text


def test_a_process_cpu_is_read_from_proc_and_a_sleeping_one_spends_none() -> None:
    spin = (
        "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.5: pass\n"
        "print('spun', flush=True)\ntime.sleep(30)"
    )
    child = subprocess.Popen([sys.executable, "-c", spin], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None and child.stdout.readline() == "spun\n"
        first = cpu_seconds(child.pid)
        time.sleep(0.3)
        assert first == pytest.approx(0.5, abs=0.25)  # the interpreter's start-up on top of the spin
        assert cpu_seconds(child.pid) - first < 0.02
    finally:
        child.kill()
        child.wait()
    assert cpu_seconds(os.getpid()) > 0


def test_windows_are_foreign_and_take_the_kinds_in_turn_a_noise_free_one_among_them() -> None:
    drawn = documents(len(KINDS) + 1, seed=7)
    assert [int(d["window_id"].split("-")[0]) for d in drawn] == [*range(len(KINDS)), 0]
    assert all(d["actuator_id"].startswith("foreign/") for d in drawn) and len({d["window_id"] for d in drawn}) == 9
    k = KINDS.index("thesis without sensor noise")
    assert drawn[k]["signals"] == draw(7 + k, "thesis", noise_level=0.0).document["signals"]
