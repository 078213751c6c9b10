"""A live service for the tests that need one: a free port, and ``ema serve`` started on it, warm."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

# The pipeline's smallest sizes that still answer: a live server's tests are about the service, not accuracy.
SMALL_ENV = {
    "EMA_PIPELINE__N_SIMULATIONS": "16",
    "EMA_PIPELINE__CHECK_WINDOWS": "8",
    "EMA_PIPELINE__N_TIMESTEPS": "50",
    "EMA_PIPELINE__HIDDEN_UNITS": "8",
}


def free_port() -> int:
    """A port on 127.0.0.1 no one listens on now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def start_server(port: int, database: Path) -> subprocess.Popen:
    """``ema serve`` on ``port`` with ``database`` and ``SMALL_ENV``, returned once /healthz says warm."""
    env = {**os.environ, **SMALL_ENV}
    command = [sys.executable, "-m", "ema.cli.main", "serve", "--port", str(port), "--database", str(database)]
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
