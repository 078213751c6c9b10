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


def start_server(port: int, database: Path | str, **env_extra: str) -> subprocess.Popen:
    """``ema serve`` on ``port`` with ``database`` (a file or a postgresql:// address) and ``SMALL_ENV``, returned
    once /healthz says warm."""
    env = {**os.environ, **SMALL_ENV, **env_extra}
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


class PostgresServer:
    """A PostgreSQL server of our own for the tests: Debian's binaries, a data folder under ``folder``, a free port
    on 127.0.0.1, trust authentication; run as the ``postgres`` user where the tests run as root (PostgreSQL
    refuses root). ``unavailable()`` says why none can start here (the tests that need one skip, saying so)."""

    BIN = sorted(Path("/usr/lib/postgresql").glob("*/bin"))

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.port = free_port()
        self.data = folder / "data"
        self.process: subprocess.Popen | None = None

    @classmethod
    def unavailable(cls) -> str | None:
        if not cls.BIN or not (cls.BIN[-1] / "initdb").exists():
            return "no PostgreSQL server binaries (Debian's postgresql package) on this machine"
        if os.geteuid() == 0:
            import pwd

            try:
                pwd.getpwnam("postgres")
            except KeyError:
                return "running as root with no 'postgres' user to run the server as"
        return None

    def _as_server_user(self, command: list[str]) -> list[str]:
        return ["runuser", "-u", "postgres", "--", *command] if os.geteuid() == 0 else command

    def start(self) -> str:
        """Start it; returns its address (``postgresql://postgres@127.0.0.1:PORT/postgres``)."""
        import shutil

        bin_dir = self.BIN[-1]
        self.folder.mkdir(parents=True, exist_ok=True)
        if os.geteuid() == 0:
            shutil.chown(self.folder, "postgres")
        initdb = [str(bin_dir / "initdb"), "-D", str(self.data), "-A", "trust", "-U", "postgres", "--no-sync"]
        subprocess.run(self._as_server_user(initdb), check=True, capture_output=True)
        server = [
            str(bin_dir / "postgres"),
            "-D",
            str(self.data),
            "-p",
            str(self.port),
            "-h",
            "127.0.0.1",
            "-k",
            str(self.folder),
            "-c",
            "fsync=off",
            "-c",
            "max_connections=200",
        ]
        self.process = subprocess.Popen(self._as_server_user(server), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        ready = [str(bin_dir / "pg_isready"), "-h", "127.0.0.1", "-p", str(self.port)]
        deadline = time.monotonic() + 60
        while subprocess.run(ready, capture_output=True).returncode != 0:
            if time.monotonic() > deadline or self.process.poll() is not None:
                said = self.process.stderr.read().decode() if self.process.stderr is not None else ""
                raise RuntimeError(f"PostgreSQL did not start: {said[-500:]}")
            time.sleep(0.2)
        return self.address()

    def address(self, database: str = "postgres") -> str:
        return f"postgresql://postgres@127.0.0.1:{self.port}/{database}"

    def create_database(self, name: str) -> str:
        import psycopg

        with psycopg.connect(self.address(), autocommit=True) as connection:
            connection.execute(f'CREATE DATABASE "{name}"')
        return self.address(name)

    def stop(self) -> None:
        if self.process is not None:
            self.process.terminate()
            self.process.wait(timeout=30)
