"""An ``ema`` command run as a user runs it: a fresh process, its wall time from start to exit, its ``--json``
answer."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from typing import Any


def run_ema(*arguments: str) -> tuple[float, Any]:
    """(wall seconds, the parsed JSON it printed) of ``ema <arguments> --json``; a failure raises with its output."""
    command = [sys.executable, "-m", "ema.cli.main", *arguments, "--json"]
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=True)
    return time.perf_counter() - started, json.loads(done.stdout)
