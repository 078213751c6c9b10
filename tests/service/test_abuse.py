"""A live server (uvicorn in its own process) probed as a careless or hostile client would."""

import concurrent.futures
import json
import os
import socket
import subprocess
import sys
import threading
import time

import httpx
import pytest

from tests.servers import SMALL_ENV, free_port
from tests.service.conftest import KEY

SERVER = """
import uvicorn
from ema.service.config import Settings
from ema.service.main import create_app
uvicorn.run(create_app(Settings()), host="127.0.0.1", port={port}, log_level="warning")
"""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    port = free_port()
    env = {
        **os.environ,
        "EMA_API_KEY": KEY,
        "EMA_DATABASE": str(tmp_path_factory.mktemp("live") / "history.sqlite3"),
        "EMA_MAX_QUEUE": "2",
        "EMA_WARM_UP": "false",
        **SMALL_ENV,
        "EMA_BODY_TIMEOUT_S": "4",
        "EMA_BODY_GRACE_S": "2",
        "EMA_MAX_BODY_BYTES": "5000000",
    }
    log = (tmp_path_factory.mktemp("log") / "server.log").open("w")
    process = subprocess.Popen([sys.executable, "-c", SERVER.format(port=port)], env=env, stderr=log)
    url = f"http://127.0.0.1:{port}"
    process.log_path = log.name  # type: ignore[attr-defined]
    for _ in range(300):
        try:
            if httpx.get(f"{url}/healthz", timeout=1).status_code == 200:
                break
        except httpx.HTTPError:
            time.sleep(0.1)
    yield url, process.log_path
    process.terminate()
    process.wait(timeout=30)
    log.close()


@pytest.fixture
def live(server):
    return server[0]


def _post(url: str, body, key: str = KEY, path: str = "/v1/estimate", timeout: float = 120) -> httpx.Response:
    content = body if isinstance(body, bytes) else json.dumps(body).encode()
    headers = {"content-type": "application/json", "x-api-key": key}
    return httpx.post(url + path, content=content, headers=headers, timeout=timeout)


def test_a_burst_on_an_idle_server_admits_one_plus_the_queue_and_refuses_the_rest_at_once(live, window_document):
    windows = [{**window_document, "window_id": f"burst-{i}"} for i in range(20)]
    started = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(20) as pool:
        futures = [pool.submit(lambda w: (_post(live, w), time.perf_counter() - started), w) for w in windows]
        answers = [f.result() for f in futures]
    accepted = [r for r, _ in answers if r.status_code == 200]
    refused = [(r, t) for r, t in answers if r.status_code == 503]
    assert len(accepted) + len(refused) == 20
    assert 1 <= len(accepted) <= 1 + 2
    assert all(int(r.headers["Retry-After"]) >= 1 for r, _ in refused)
    assert max(t for _, t in refused) < 2.0


def test_wrong_keys_are_refused_before_the_body_is_read(live):
    big = b'{"schema": "ema-window/1", "pad": "' + b"x" * 48_000_000 + b'"}'
    started = time.perf_counter()
    assert _post(live, big, key="wrong").status_code == 401
    assert time.perf_counter() - started < 3.0
    non_ascii = httpx.post(f"{live}/v1/estimate", content=b"{}", headers=[(b"x-api-key", "clé".encode())], timeout=10)
    assert non_ascii.status_code == 401
    assert httpx.post(f"{live}/v1/estimate", content=b"{not json", timeout=10).status_code == 401


def test_an_oversized_window_is_refused_at_once_and_healthz_stays_quick(live, window_document):
    long = {**window_document, "window_id": "long", "sample_rate_hz": 1000.0}  # 1000 samples at 1 kHz: 1 s...
    long["signals"] = {k: v * 12 for k, v in window_document["signals"].items()}  # ... times 12: 12 s > 10 s
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        refused = pool.submit(_post, live, long)
        time.sleep(0.05)
        started = time.perf_counter()
        assert httpx.get(f"{live}/healthz", timeout=5).status_code == 200
        assert time.perf_counter() - started < 1.0
        response = refused.result()
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"] == ["body", "signals"]


def test_a_huge_seed_is_a_422_not_a_500(live, window_document):
    response = _post(live, {**window_document, "window_id": "seed"}, path="/v1/estimate?seed=18446744073709551616")
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["query", "seed"]


def test_a_window_posted_twice_is_stored_once(live, window_document):
    window = {**window_document, "window_id": "twice"}
    first, second = _post(live, window), _post(live, window)
    assert first.status_code == second.status_code == 200
    assert second.json()["replay"] is True and second.json()["id"] == first.json()["id"]
    history = httpx.get(f"{live}/v1/actuators/ac-1/elev/estimates", headers={"x-api-key": KEY}, timeout=10).json()
    assert [h["window_id"] for h in history["estimates"]].count("twice") == 1


def _trickle(url: str, stop: threading.Event) -> None:
    """A body announced at 100 kB that arrives a byte every 0.3 s (on a raw socket: no client library waits)."""
    host, port = url.removeprefix("http://").split(":")
    with socket.create_connection((host, int(port))) as connection:
        head = (
            f"POST /v1/estimate HTTP/1.1\r\nHost: 127.0.0.1\r\nX-API-Key: {KEY}\r\n"
            "Content-Type: application/json\r\nContent-Length: 100000\r\n\r\n"
        )
        connection.sendall(head.encode())
        while not stop.wait(0.3):
            try:
                connection.sendall(b" ")
            except OSError:
                return


def test_slow_uploads_hold_their_connections_not_the_queue(live, window_document):
    stop = threading.Event()
    trickles = [threading.Thread(target=_trickle, args=(live, stop)) for _ in range(8)]
    for thread in trickles:
        thread.start()
    try:
        time.sleep(1.0)
        answer = _post(live, {**window_document, "window_id": "beside-slow-uploads"})
        assert answer.status_code == 200, answer.text
        assert httpx.get(f"{live}/healthz", timeout=5).json()["queued"] == 0
    finally:
        stop.set()
        for thread in trickles:
            thread.join()


def test_a_body_that_does_not_arrive_in_time_is_a_408_and_an_abandoned_one_leaves_no_traceback(server):
    url, log_path = server
    host, port = url.removeprefix("http://").split(":")
    head = (
        f"POST /v1/estimate HTTP/1.1\r\nHost: 127.0.0.1\r\nX-API-Key: {KEY}\r\n"
        "Content-Type: application/json\r\nContent-Length: 1000\r\n\r\n{"
    )
    with socket.create_connection((host, int(port)), timeout=30) as connection:
        connection.sendall(head.encode())
        assert b" 408 " in connection.recv(4096).split(b"\r\n")[0] + b" "
    with socket.create_connection((host, int(port)), timeout=30) as connection:
        connection.sendall(head.encode())
        time.sleep(0.5)  # the client leaves half-way through its body
    time.sleep(1.0)
    with open(log_path) as log:
        assert "Traceback" not in log.read()


def test_a_trickle_is_cut_off_once_its_pace_falls_under_the_minimum(live):
    host, port = live.removeprefix("http://").split(":")
    head = (
        f"POST /v1/estimate HTTP/1.1\r\nHost: 127.0.0.1\r\nX-API-Key: {KEY}\r\n"
        "Content-Type: application/json\r\nContent-Length: 100000\r\n\r\n"
    )
    with socket.create_connection((host, int(port)), timeout=30) as connection:
        connection.sendall(head.encode())
        started = time.perf_counter()
        for _ in range(20):  # a byte every 0.1 s: 10 B/s, far under the 1000 B/s kept after the 2 s grace
            try:
                connection.sendall(b" ")
            except OSError:
                break
            time.sleep(0.1)
        status = connection.recv(4096).split(b"\r\n")[0]
    assert b" 408 " in status + b" " and time.perf_counter() - started < 4.0  # cut at the grace, not the timeout


def test_copies_of_one_window_posted_at_once_are_computed_once(live, window_document):
    window = {**window_document, "window_id": "copies-at-once"}
    with concurrent.futures.ThreadPoolExecutor(3) as pool:
        answers = [f.result() for f in [pool.submit(_post, live, window) for _ in range(3)]]
    assert [a.status_code for a in answers] == [200, 200, 200]
    assert len({a.json()["id"] for a in answers}) == 1
    assert sorted(a.json()["replay"] for a in answers) == [False, True, True]  # one run, two answers from it


def test_a_refusal_sent_before_the_body_is_read_reaches_a_plain_python_client(live):
    import urllib.error
    import urllib.request

    body = b"{" + b" " * 8_000_000 + b"}"  # over this server's 5 MB: refused from its declared length
    request = urllib.request.Request(
        f"{live}/v1/estimate", data=body, headers={"content-type": "application/json", "x-api-key": KEY}
    )
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(request, timeout=30)
    assert refused.value.code == 413
