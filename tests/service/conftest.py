import copy
import time
from collections.abc import Callable

import pytest
from fastapi.testclient import TestClient

from ema.estimate.config import PipelineConfig
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.params import HealthParams
from ema.model.window import window_to_dict
from ema.service.config import Settings
from ema.service.main import create_app

SMALL = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=50, hidden_units=8)
KEY = "a-key-of-sixteen-characters"
LOCAL = "http://127.0.0.1"  # without a key the service answers loopback hosts only


def settled(client: TestClient, timeout_s: float = 120.0) -> None:
    """Wait until the service's keeper has brought every fleet line up to date (none pending)."""
    settled_lines(lambda: client.get("/v1/actuators").json(), timeout_s)


def settled_lines(read_lines: Callable[[], list[dict]], timeout_s: float = 120.0) -> None:
    """Wait until none of the fleet's lines ``read_lines`` returns (``GET /v1/actuators``) is pending: the keeper
    computes them after a start or a store, and a page read before then shows them pending."""
    deadline = time.monotonic() + timeout_s
    while any(line["status"] == "pending" for line in read_lines()):
        assert time.monotonic() < deadline, "the fleet's lines were not brought up to date"
        time.sleep(0.1)


def settings_for(tmp_path, **overrides) -> Settings:
    return Settings(database=tmp_path / "history.sqlite3", pipeline=SMALL, warm_up=False, **overrides)


@pytest.fixture(scope="session")
def window_document() -> dict:
    window = synthetic_window(HealthParams.single(0.1, 0.055, 0.8), seed=3, duration_s=0.1, actuator_id="ac-1/elev")
    return window_to_dict(window)


@pytest.fixture
def document(window_document) -> dict:
    return copy.deepcopy(window_document)


@pytest.fixture
def settings(tmp_path) -> Settings:
    return settings_for(tmp_path)


@pytest.fixture
def client(settings):
    with TestClient(create_app(settings), base_url=LOCAL) as test_client:
        yield test_client
