"""The robustness probe: seven attacks a hostile client or a failing machine makes, each on a fresh ``ema serve``.

1. two windows at flight hours 0 and 1e150: /ui stays 200;
2. the history deleted under the running service: no window is answered 200 and then lost;
3. a read-only history: refused at start, or posts refused in under a second;
4. beside 8 trickling uploads a normal post is answered within 15 s;
5. 4 copies of one window posted at once: the slowest answer within 2x a single one;
6. 600 actuators of 8 windows, the service restarted: 5 viewers reloading /ui as a browser does (one connection,
   the ETag sent back) beside an estimate, the estimate answered in 2 s or less and within 1.5x its time alone,
   and every /ui in 10 s or less (the lines are the keeper's work, the pages take turns in the view's share);
7. a path id with a NUL, an RTL override or 10,000 characters is refused, and so is one shaped like a route.

``python -m benchmarks.robustness_probe [--docs]`` (``--docs`` writes its section of docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import contextlib
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse
from collections.abc import Callable, Iterator
from pathlib import Path

import httpx

from ema.cli.benchmark_docs import write_section
from ema.estimate.documents import parameter
from ema.history.open import open_history
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.window import window_to_dict
from tests.servers import SMALL_ENV, free_port
from tests.service.conftest import SMALL

COMMAND = "python -m benchmarks.robustness_probe --docs"


@contextlib.contextmanager
def served(database: Path, **env: str) -> Iterator[tuple[str, subprocess.Popen]]:
    """A fresh ``ema serve`` on ``database`` (small pipeline sizes), its URL and process; stopped on leaving."""
    port = free_port()
    command = [sys.executable, "-m", "ema", "serve", "--port", str(port), "--database", str(database)]
    environment = {**os.environ, **SMALL_ENV, **env}
    process = subprocess.Popen(command, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline and process.poll() is None:
        with contextlib.suppress(httpx.HTTPError):
            if httpx.get(f"{url}/healthz", timeout=2).json()["warm"]:
                break
        time.sleep(0.3)
    try:
        yield url, process
    finally:
        process.kill()
        process.wait(timeout=30)


def window(window_id: str, actuator_id: str = "probe/elevator", **extra: object) -> dict:
    w = synthetic_window(HealthParams.single(), seed=hash(window_id) % 1000, duration_s=0.1, actuator_id=actuator_id)
    return {**window_to_dict(w), "window_id": window_id, **extra}


def post(url: str, body: dict, timeout: float = 120) -> httpx.Response:
    return httpx.post(f"{url}/v1/estimate", json=body, timeout=timeout)


def huge_hours(folder: Path) -> str:
    with served(folder / "h.sqlite3") as (url, _):
        answers = [post(url, window("h0", flight_hours=0.0)).status_code]
        answers.append(post(url, window("h1", flight_hours=1e150)).status_code)
        page = httpx.get(f"{url}/ui", timeout=60).status_code
    return f"posted: {answers}; /ui {page}" + (" — pass" if page == 200 else " — FAIL")


def deleted_history(folder: Path) -> str:
    database = folder / "d.sqlite3"
    answered = []  # after the deletion (what was stored before went with the file)
    with served(database) as (url, _):
        post(url, window("d0"))
        for suffix in ("", "-wal", "-shm"):
            Path(f"{database}{suffix}").unlink(missing_ok=True)
        for i in range(1, 4):
            answer = post(url, window(f"d{i}"))
            if answer.status_code == 200:
                answered.append(f"d{i}")
    store = open_history(database)  # a new file: what a restarted service would read
    kept = {s.window_id for s in store.history("probe/elevator")[0]}
    store.close()
    lost = [w for w in answered if w not in kept]
    return f"answered 200 after the deletion: {len(answered)}; of them lost: {len(lost)}" + (
        " — pass" if not lost else " — FAIL"
    )


def read_only(folder: Path) -> str:
    database = folder / "r.sqlite3"
    open_history(database).close()
    database.chmod(0o400)
    started = time.perf_counter()
    with served(database) as (_, process):
        code = process.wait(timeout=60)
    return f"ema serve exited {code} in {time.perf_counter() - started:.1f} s" + (" — pass" if code == 2 else " — FAIL")


def _trickle(url: str, stop: threading.Event) -> None:
    host, port = url.removeprefix("http://").split(":")
    with socket.create_connection((host, int(port))) as connection:
        head = "POST /v1/estimate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
        connection.sendall((head + "Content-Length: 100000\r\n\r\n").encode())
        while not stop.wait(1.0):
            try:
                connection.sendall(b" ")
            except OSError:
                return


def trickles(folder: Path) -> str:
    with served(folder / "t.sqlite3") as (url, _):
        stop = threading.Event()
        threads = [threading.Thread(target=_trickle, args=(url, stop)) for _ in range(8)]
        for thread in threads:
            thread.start()
        time.sleep(1.0)
        started = time.perf_counter()
        status = post(url, window("beside-trickles")).status_code
        seconds = time.perf_counter() - started
        stop.set()
        for thread in threads:
            thread.join()
    ok = status == 200 and seconds < 15
    return f"HTTP {status} in {seconds:.2f} s" + (" — pass" if ok else " — FAIL")


def copies(folder: Path) -> str:
    with served(folder / "c.sqlite3") as (url, _):
        post(url, window("warm"))
        started = time.perf_counter()
        post(url, window("single"))
        single = time.perf_counter() - started

        def timed(_: int) -> float:
            began = time.perf_counter()
            post(url, window("four-copies"))
            return time.perf_counter() - began

        with concurrent.futures.ThreadPoolExecutor(4) as pool:
            slowest = max(pool.map(timed, range(4)))
    ratio = slowest / single
    return f"single {single:.2f} s, slowest of 4 copies {slowest:.2f} s ({ratio:.2f}x)" + (
        " — pass" if ratio <= 2 else " — FAIL"
    )


def _fleet(database: Path, actuators: int, windows: int) -> None:
    """``actuators`` of ``windows`` windows each, stored as a fleet run would (no service, so no line kept)."""
    base = estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)
    store = open_history(database)
    for a in range(actuators):
        for w in range(windows):
            info = base.window.model_copy(update={"flight_hours": 10.0 * w, "content_sha256": f"{a}-{w}"})
            fdj = parameter(0.05 + 1e-4 * w * (a % 3), 3e-4, 0.05, unit="N·m")
            update = {"actuator_id": f"tail-{a // 4}/ema-{a % 4}", "window_id": f"w{w}", "window": info}
            store.add(base.model_copy(update={**update, "estimates": base.estimates.model_copy(update={"FDJ": fdj})}))
    store.close()


def _viewer(url: str, stop: threading.Event, times: list[float]) -> None:
    """A browser reloading /ui as fast as it can: one kept-alive connection, the page's ETag sent back."""
    tag = ""
    with httpx.Client(timeout=120) as client:
        while not stop.is_set():
            started = time.perf_counter()
            answer = client.get(f"{url}/ui", headers={"If-None-Match": tag} if tag else {})
            tag = answer.headers.get("etag", tag)
            times.append(time.perf_counter() - started)


def _estimates(url: str, name: str, repeats: int = 3) -> tuple[float, bool]:
    """The median time of ``repeats`` posts of fresh windows, and whether every one was answered 200."""
    times, ok = [], True
    for repeat in range(repeats):
        started = time.perf_counter()
        ok &= post(url, window(f"{name}-{repeat}", actuator_id=f"probe/{name}")).status_code == 200
        times.append(time.perf_counter() - started)
    return sorted(times)[repeats // 2], ok


def big_fleet(folder: Path) -> str:
    database = folder / "f.sqlite3"
    _fleet(database, 600, 8)
    with served(database) as (url, _):
        post(url, window("warm", actuator_id="probe/warm"))  # the kernels loaded: the timing is the estimate's
        alone, alone_ok = _estimates(url, "alone")
        stop, pages = threading.Event(), list[float]()
        viewers = [threading.Thread(target=_viewer, args=(url, stop, pages)) for _ in range(5)]
        for viewer in viewers:
            viewer.start()
        time.sleep(1.0)
        beside, beside_ok = _estimates(url, "beside")
        stop.set()
        for viewer in viewers:
            viewer.join()
    ok = alone_ok and beside_ok and beside <= min(2.0, 1.5 * alone) and max(pages) <= 10.0
    return (
        f"an estimate alone {alone:.2f} s, beside 5 viewers {beside:.2f} s ({beside / alone:.2f}x, medians of 3); "
        f"{len(pages)} /ui loads, the slowest {max(pages):.2f} s" + (" — pass" if ok else " — FAIL")
    )


def path_ids(folder: Path) -> str:
    codes = []
    with served(folder / "p.sqlite3") as (url, _):
        for bad in ["a\x00b", "tail-1/\u202eleft", "x" * 10_000, "sh/estimates"]:
            path = f"{url}/v1/actuators/{urllib.parse.quote(bad)}"
            codes.append(httpx.put(path, json=THESIS.model_dump(by_alias=True), timeout=30).status_code)
    return f"HTTP {codes}" + (" — pass" if all(c == 422 for c in codes) else " — FAIL")


CHECKS: list[tuple[str, Callable[[Path], str]]] = [
    ("flight hours 0 and 1e150, then /ui", huge_hours),
    ("the history deleted under the service", deleted_history),
    ("a read-only history", read_only),
    ("a post beside 8 trickling uploads", trickles),
    ("4 copies of one window at once", copies),
    ("5 viewers of /ui beside an estimate, 600 actuators, restarted", big_fleet),
    ("path ids with NUL, RTL override, 10,000 characters, a route's shape", path_ids),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--docs", action="store_true", help="rewrite its section of docs/benchmarks.md")
    args = parser.parse_args()
    rows = []
    for name, check in CHECKS:
        folder = Path(tempfile.mkdtemp(prefix="ema-probe-"))
        try:
            outcome = check(folder)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        print(f"{name}: {outcome}", flush=True)
        rows.append(f"| {name} | {outcome} |")
    body = (
        "Seven attacks, each on a fresh `ema serve` (small pipeline sizes) on this machine. Timings are wall "
        "clock on a 2-core machine, compared within the run.\n\n| check | outcome |\n|---|---|\n" + "\n".join(rows)
    )
    if args.docs:
        write_section("Robustness probe", COMMAND, body)
    print(json.dumps({"rows": rows}))


if __name__ == "__main__":
    main()
