"""A history of each kind for the contract tests: SQLite in a file, PostgreSQL on a server the session starts."""

import shutil
import tempfile
import uuid
from pathlib import Path

import pytest

from ema.estimate.pipeline import estimate_window
from ema.history.open import open_history
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.synthetic import synthetic_window
from tests.servers import PostgresServer
from tests.service.conftest import SMALL


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


@pytest.fixture(params=["sqlite", "postgres"])
def setting(request, tmp_path) -> str:
    """The database setting of a new, empty history of each kind."""
    if request.param == "sqlite":
        return str(tmp_path / "history.sqlite3")
    server = request.getfixturevalue("postgres")
    return server.create_database(f"ema_{uuid.uuid4().hex[:12]}")


@pytest.fixture
def history(setting):
    store = open_history(setting)
    yield store
    store.close()


@pytest.fixture(scope="session")
def result():
    return estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)
