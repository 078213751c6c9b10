"""The HTTP contract through TestClient: answers, stored history, errors naming fields, overload."""

import threading

import pytest
from fastapi.testclient import TestClient

from service.config import Settings
from service.main import create_app
from service.routes import estimate as estimate_route
from tests.service.conftest import SMALL


def test_healthz_says_warm(client):
    health = client.get("/healthz").json()
    assert health["status"] == "ok" and health["warm"] is True


def test_estimate_answers_the_contract_and_is_stored(client, document):
    response = client.post("/v1/estimate", json=document)
    assert response.status_code == 200, response.text
    result = response.json()
    assert result["schema"] == "ema-estimate/1"
    assert set(result["estimates"]) >= {"FDJ", "eta_O", "eta_A", "FSJ"}
    assert result["estimates"]["FDJ"]["std"] > 0
    assert set(result["timings_s"]) == {"simulate", "train", "predict", "total"}
    assert result["dataset"]["n_simulations"] == SMALL["n_simulations"]
    history = client.get("/v1/actuators/ac-1/elev/estimates").json()
    assert [h["id"] for h in history["estimates"]] == [result["id"]]
    assert history["trend"]["FDJ"]["n"] == 1 and history["trend"]["FDJ"]["slope_per_day"] is None


def test_sizes_are_overridable_within_bounds(client, document):
    ok = client.post("/v1/estimate?n_simulations=30&hidden_units=5", json=document)
    assert ok.status_code == 200 and ok.json()["dataset"]["n_simulations"] == 30
    too_big = client.post("/v1/estimate?n_simulations=100000", json=document)
    assert too_big.status_code == 422
    assert too_big.json()["detail"][0]["loc"] == ["query", "n_simulations"]
    longer_than_window = client.post("/v1/estimate?n_timesteps=4000", json=document)  # 1000 samples
    assert longer_than_window.json()["detail"][0]["loc"] == ["query", "n_timesteps"]


def _set(document, path, value):
    target = document
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return document


@pytest.mark.parametrize(
    ("path", "value", "loc"),
    [
        (("signals", "current_a"), [0.0] * 10, ["body", "signals", "current_a"]),
        (("signals", "position_deg"), [50.0] * 1000, ["body", "signals", "position_deg"]),
        (("sample_rate_hz",), 50.0, ["body", "sample_rate_hz"]),
        (("flight_condition", "altitude_m"), 20_000.0, ["body", "flight_condition", "altitude_m"]),
        (("schema",), "ema-window/9", ["body", "schema"]),
        (("signals", "torque"), [0.0], ["body", "signals", "torque"]),
    ],
)
def test_bad_windows_get_422_naming_the_field(client, document, path, value, loc):
    response = client.post("/v1/estimate", json=_set(document, path, value))
    assert response.status_code == 422
    assert loc in [error["loc"] for error in response.json()["detail"]]


def test_too_short_and_nan_and_not_json(client, document):
    short = {**document, "signals": {name: values[:50] for name, values in document["signals"].items()}}
    response = client.post("/v1/estimate", json=short)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "signals"]
    raw = '{"schema": "ema-window/1", "actuator_id": "a", "window_id": "w", "sample_rate_hz": NaN}'
    response = client.post("/v1/estimate", content=raw, headers={"content-type": "application/json"})
    assert response.status_code == 422
    assert ["body", "sample_rate_hz"] in [e["loc"] for e in response.json()["detail"]]
    response = client.post("/v1/estimate", content="{not json", headers={"content-type": "application/json"})
    assert response.status_code == 422


def test_oversize_body_is_refused(tmp_path, document):
    settings = Settings(database=tmp_path / "h.sqlite3", max_body_bytes=10_000, **SMALL)
    with TestClient(create_app(settings)) as client:
        response = client.post("/v1/estimate", json=document)
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body"]


def test_api_key_protects_v1_but_not_healthz(tmp_path, document):
    settings = Settings(database=tmp_path / "h.sqlite3", api_key="s3cret", **SMALL)
    with TestClient(create_app(settings)) as client:
        assert client.get("/healthz").status_code == 200
        assert client.get("/v1/actuators/x/estimates").status_code == 401
        assert client.get("/v1/actuators/x/estimates", headers={"x-api-key": "wrong"}).status_code == 401
        assert client.get("/v1/actuators/x/estimates", headers={"x-api-key": "s3cret"}).status_code == 200


@pytest.fixture
def blocked(monkeypatch):
    """The pipeline holds its slot until ``release`` is set; ``started`` says it holds it."""
    release, started = threading.Event(), threading.Event()
    real = estimate_route.estimate_window

    def slow_pipeline(window, config):
        started.set()
        release.wait(timeout=30)
        return real(window, config)

    monkeypatch.setattr(estimate_route, "estimate_window", slow_pipeline)
    return release, started


def _second_while_first_runs(settings, document, blocked, during=lambda client: None):
    """Post once in a thread, and once more while the first holds the slot; both responses."""
    release, started = blocked
    with TestClient(create_app(settings)) as client:
        first: dict = {}
        worker = threading.Thread(target=lambda: first.update(r=client.post("/v1/estimate", json=document)))
        worker.start()
        assert started.wait(timeout=30)
        second = client.post("/v1/estimate", json=document)
        during(client)
        release.set()
        worker.join(timeout=60)
    return first["r"], second


def test_a_full_queue_answers_503_with_retry_after(tmp_path, document, blocked):
    settings = Settings(database=tmp_path / "h.sqlite3", max_queue=0, **SMALL)

    def loop_still_answers(client):
        assert client.get("/healthz").json()["running"] == 1

    first, busy = _second_while_first_runs(settings, document, blocked, loop_still_answers)
    assert busy.status_code == 503
    assert int(busy.headers["Retry-After"]) >= 1
    assert first.status_code == 200


def test_a_queued_request_that_cannot_start_in_time_gets_503(tmp_path, document, blocked):
    settings = Settings(database=tmp_path / "h.sqlite3", max_queue=5, queue_timeout_s=0.5, **SMALL)
    first, waited = _second_while_first_runs(settings, document, blocked)  # queued, gives up after 0.5 s
    assert waited.status_code == 503
    assert first.status_code == 200


def test_history_survives_a_restart(tmp_path, document):
    settings = Settings(database=tmp_path / "h.sqlite3", **SMALL)
    with TestClient(create_app(settings)) as client:
        first = client.post("/v1/estimate", json=document).json()
        second = client.post("/v1/estimate", json={**document, "window_id": "w2"}).json()
    with TestClient(create_app(settings)) as client:
        history = client.get("/v1/actuators/ac-1/elev/estimates").json()
    assert [h["id"] for h in history["estimates"]] == [first["id"], second["id"]]  # oldest first
    assert history["trend"]["eta_O"]["n"] == 2


def test_calibrate_answers_the_report(client, document):
    response = client.post("/v1/calibrate", json={"windows": [document], "truth": {"FDJ": 0.055, "eta_O": 0.8}})
    assert response.status_code == 200, response.text
    report = response.json()
    assert report["schema"] == "ema-calibration/1"
    assert {"residual_rms_before", "candidates", "selected_effect", "error_before"} <= set(report)


def test_calibrate_bad_input_is_named(client, document):
    assert client.post("/v1/calibrate", json={"windows": []}).json()["detail"][0]["loc"] == ["body", "windows"]
    response = client.post("/v1/calibrate", json={"windows": [document], "truth": {"FDJ": -1, "eta_O": 0.8}})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "truth", "FDJ"]
