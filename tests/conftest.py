"""Every test compiles its kernels as the product does; the session's PostgreSQL server, started where asked.

Run in parallel (pytest-xdist, one worker a core), each worker has a core of its own: its budget (and that of every
process it starts) is one thread, as a fleet worker's is, so two workers never share a core.

Numba's cache does not key on LLVM's interleaving option (``ema.model.runtime``): a test that calls a kernel
directly, first in a fresh checkout, would leave the cache a kernel ~1.3x slower for every later process.
"""

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from tests.servers import PostgresServer


def pytest_configure(config: pytest.Config) -> None:
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")
    if worker.startswith("gw") and hasattr(os, "sched_setaffinity"):
        cores = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {cores[int(worker[2:]) % len(cores)]})


@pytest.fixture(autouse=True, scope="session")
def _compiler_options() -> None:
    from ema.model import runtime

    runtime.compiler_options()


@pytest.fixture(scope="session")
def postgres():
    """A PostgreSQL server for the session, or a skip saying why none can start here."""
    why = PostgresServer.unavailable()
    if why is not None:
        pytest.skip(why)
    folder = Path(tempfile.mkdtemp(prefix="ema-pg-"))  # outside pytest's folder: the server's user must enter it
    server = PostgresServer(folder)
    try:
        server.start()
    except Exception as exc:  # a machine that cannot run one: said, not failed
        shutil.rmtree(folder, ignore_errors=True)
        pytest.skip(f"PostgreSQL could not start here: {exc}")
    yield server
    server.stop()
    shutil.rmtree(folder, ignore_errors=True)
