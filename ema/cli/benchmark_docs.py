"""Write a benchmark's figures into one section of docs/benchmarks.md (machine, date, command, figures)."""

from __future__ import annotations

import datetime as dt
import os
import platform
import re
import shlex
import sys
from pathlib import Path

BENCHMARKS_MD = Path("docs/benchmarks.md")  # relative to the checkout the benchmark runs in
HEADER = (
    "# Benchmarks\n\nEach section is rewritten by the command it names; figures from one run are compared as ratios.\n"
)


def machine() -> str:
    """CPU model and core count, the context every figure needs."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}"


def typed_command() -> str:
    """This process's command line as typed (``python -m benchmarks.x --flag v --docs``): the figures' section says
    the arguments they came from, never a fixed text that omits some."""
    return shlex.join(["python", *sys.orig_argv[1:]])


def write_section(title: str, command: str, body: str, path: Path = BENCHMARKS_MD) -> None:
    """Replace (or append) the section ``## title`` of the benchmarks file."""
    stamp = dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    section = f"## {title}\n\n- machine: {machine()}\n- date: {stamp}\n- command: `{command}`\n\n{body.strip()}\n"
    text = path.read_text() if path.exists() else HEADER
    pattern = re.compile(rf"^## {re.escape(title)}\n.*?(?=^## |\Z)", re.S | re.M)
    text = pattern.sub(lambda _: section + "\n", text) if pattern.search(text) else text.rstrip() + "\n\n" + section
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
