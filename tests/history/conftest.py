"""A history of each kind for the contract tests: SQLite in a file, PostgreSQL on the session's server
(``tests/conftest.py``)."""

import uuid

import pytest

from ema.history.open import open_history
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from tests.service.conftest import SMALL


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
