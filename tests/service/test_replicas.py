"""Two ``ema serve`` replicas on one PostgreSQL are one service: one row per window, one 409, one version each,
nothing answered 200 lost when one is killed, and the whole fleet on either's page."""

import concurrent.futures
import signal
import uuid

import httpx
import pytest

from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.window import window_to_dict
from tests.servers import free_port, start_server


def _window(window_id: str, actuator_id: str = "tail-9/elevator") -> dict:
    w = synthetic_window(
        HealthParams.single(), seed=abs(hash(window_id)) % 997, duration_s=0.1, actuator_id=actuator_id
    )
    return {**window_to_dict(w), "window_id": window_id}


@pytest.fixture
def replicas(postgres):
    address = postgres.create_database(f"replicas_{uuid.uuid4().hex[:12]}")
    ports = [free_port(), free_port()]
    servers = [start_server(port, address, EMA_WARM_UP="false", EMA_MAX_QUEUE="16") for port in ports]
    yield [f"http://127.0.0.1:{port}" for port in ports], servers
    for server in servers:
        if server.poll() is None:
            server.terminate()
            server.wait(timeout=30)


def _post(url: str, body: dict) -> httpx.Response:
    return httpx.post(f"{url}/v1/estimate", json=body, timeout=300)


def test_two_replicas_on_one_postgresql_are_one_history(replicas):
    (a, b), _ = replicas
    same = _window("same-window")
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        answers = list(pool.map(lambda url: _post(url, same), [a, b]))
    assert [r.status_code for r in answers] == [200, 200]
    first, second = (r.json() for r in answers)
    assert first["id"] == second["id"] and first["estimates"] == second["estimates"]
    for url in (a, b):
        history = httpx.get(f"{url}/v1/actuators/tail-9/elevator/estimates", timeout=30).json()
        assert [e["window_id"] for e in history["estimates"]] == ["same-window"]
        other = {**_window("other"), "window_id": "same-window"}
        conflict = _post(url, other)
        assert conflict.status_code == 409 and conflict.json()["detail"][0]["loc"] == ["body", "window_id"]
    documents = [THESIS.model_copy(update={"name": f"variant {i}"}).model_dump(by_alias=True) for i in range(4)]
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        puts = list(
            pool.map(
                lambda i: httpx.put(f"{(a, b)[i % 2]}/v1/actuators/doc/1", json=documents[i], timeout=60), range(4)
            )
        )
    assert sorted(p.json()["version"] for p in puts) == [1, 2, 3, 4]
    _post(b, _window("second-actuator", actuator_id="tail-10/elevator"))
    for url in (a, b):
        page = httpx.get(f"{url}/ui", timeout=60).text
        assert "tail-9/elevator" in page and "tail-10/elevator" in page and "doc/1" in page


def test_a_replica_killed_mid_burst_loses_nothing_it_answered(replicas):
    (a, b), (server_a, _) = replicas
    _post(a, _window("warm-up"))  # the kernels loaded: the burst is estimates, not start-up
    windows = [_window(f"burst-{i}") for i in range(10)]
    answered = []
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        futures = [pool.submit(_post, a, w) for w in windows]
        for future in concurrent.futures.as_completed(futures):
            try:
                response = future.result()
            except httpx.HTTPError:
                continue
            if response.status_code == 200:
                answered.append(response.json()["window_id"])
                if len(answered) == 3:
                    server_a.send_signal(signal.SIGKILL)
    assert len(answered) >= 3
    stored = httpx.get(f"{b}/v1/actuators/tail-9/elevator/estimates", timeout=30).json()["estimates"]
    assert set(answered) <= {e["window_id"] for e in stored}
