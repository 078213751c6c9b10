"""Every test compiles its kernels as the product does; the session's PostgreSQL server, started where asked.

Numba's cache does not key on LLVM's interleaving option (``ema.model.runtime``): a test that calls a kernel
directly, first in a fresh checkout, would leave the cache a kernel ~1.3x slower for every later process.
"""

import shutil
import tempfile
from pathlib import Path

import pytest

from tests.servers import PostgresServer


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
