"""What the service adds to the pipeline: a warm ``ema serve`` answering hidden 0.5 s windows over HTTP.

For each window, the client's wall time of ``POST /v1/estimate`` against the pipeline's own
``timings_s.total`` in the answer: the difference is the service's overhead (HTTP, the body read,
JSON parsing and validation off the event loop, the history's lookups and the SQLite commit, the
answer's serialization). Beside it, the same steps timed in-process on one window body, so the
overhead can be traced to its parts. Windows are drawn by ``tests.foreign``, each under a fresh
``window_id`` (no stored answer is reused).

    python -m benchmarks.service_overhead [--windows 20] [--docs]
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np

from ema.cli.benchmark_docs import write_section
from ema.history.open import open_history
from ema.kinds.rotary.pipeline import estimate_window
from ema.model.actuator import THESIS
from ema.model.window import WindowDocument
from tests.foreign.windows import draw

SECTION = "Service overhead"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def bodies(count: int, seed: int) -> list[bytes]:
    """``count`` hidden 0.5 s windows (thesis commands), each its own window_id, as the bytes a client posts."""
    out = []
    for i in range(count):
        document = draw(seed + i, "thesis").document
        out.append(json.dumps({**document, "window_id": f"overhead-{seed}-{i}"}).encode())
    return out


def serve(database: Path, port: int) -> subprocess.Popen[bytes]:
    environment = {**os.environ, "EMA_DATABASE": str(database), "EMA_PORT": str(port)}
    process = subprocess.Popen(
        [sys.executable, "-m", "ema.cli.main", "serve", "--port", str(port)],
        env=environment,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    last = "no answer"
    for _ in range(600):
        try:
            answer = httpx.get(f"http://127.0.0.1:{port}/healthz", timeout=1.0)
            if answer.status_code == 200:
                return process
            last = f"/healthz {answer.status_code}: {answer.text[:300]}"
        except httpx.HTTPError as error:
            last = repr(error)
        if process.poll() is not None:
            break
        time.sleep(0.2)
    process.kill()
    raise RuntimeError(f"the service did not start (exit code {process.poll()}; last: {last})")


def quiet_collector() -> None:
    """Keep this client's cyclic collector off its objects so far: it holds the pipeline's modules (to time
    the parts in-process), and a full pass over them takes tenths of a second inside some timed POST."""
    gc.collect()
    gc.freeze()


def over_http(posts: list[bytes], port: int) -> dict[str, list[float]]:
    """Wall time and the pipeline's own time of each POST, in seconds."""
    wall, pipeline = [], []
    quiet_collector()
    with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=60.0) as client:
        client.post("/v1/estimate", content=posts[0], headers={"Content-Type": "application/json"})  # warm
        for body in posts[1:]:
            started = time.perf_counter()
            answer = client.post("/v1/estimate", content=body, headers={"Content-Type": "application/json"})
            wall.append(time.perf_counter() - started)
            answer.raise_for_status()
            pipeline.append(answer.json()["timings_s"]["total"])
    return {"wall": wall, "pipeline": pipeline}


def in_process(body: bytes, database: Path) -> dict[str, float]:
    """Milliseconds of each step the service takes around the pipeline, on one body (median of 20)."""
    steps: dict[str, list[float]] = {"parse and validate": [], "to arrays": [], "store": []}
    result = None
    store = open_history(database)
    for i in range(20):
        started = time.perf_counter()
        document = WindowDocument.model_validate_json(body)
        steps["parse and validate"].append(time.perf_counter() - started)
        started = time.perf_counter()
        window = document.to_window()
        steps["to arrays"].append(time.perf_counter() - started)
        if result is None:
            result = estimate_window(window, actuator=THESIS)
        started = time.perf_counter()
        store.add(result.model_copy(update={"window_id": f"{window.window_id}-{i}"}))
        steps["store"].append(time.perf_counter() - started)
    return {name: 1000 * float(np.median(values)) for name, values in steps.items()}


def report(http: dict[str, list[float]], parts: dict[str, float], size_bytes: int) -> str:
    wall, pipeline = np.array(http["wall"]), np.array(http["pipeline"])
    overhead = wall - pipeline

    def cells(values: np.ndarray) -> str:
        return f"{1000 * np.median(values):.0f} | {1000 * np.quantile(values, 0.95):.0f}"

    lines = [
        f"{len(wall)} hidden 0.5 s windows at 10 kHz ({size_bytes / 1e6:.1f} MB of JSON each), posted one after",
        "another to a warm `ema serve` on loopback; overhead = the client's wall time less the pipeline's",
        "`timings_s.total`.",
        "",
        "| | p50 [ms] | p95 [ms] |",
        "|---|---:|---:|",
        f"| wall time of POST /v1/estimate | {cells(wall)} |",
        f"| the pipeline (timings_s.total) | {cells(pipeline)} |",
        f"| the service's overhead | {cells(overhead)} |",
        "",
        "In-process, one body, median of 20: " + ", ".join(f"{name} {ms:.1f} ms" for name, ms in parts.items()) + ".",
    ]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=20)
    parser.add_argument("--seed", type=int, default=120_000)
    parser.add_argument("--docs", action="store_true", help="rewrite the section of docs/benchmarks.md")
    args = parser.parse_args()
    posts = bodies(args.windows + 1, args.seed)
    with tempfile.TemporaryDirectory() as folder:
        port = free_port()
        process = serve(Path(folder) / "history.sqlite3", port)
        try:
            http = over_http(posts, port)
        finally:
            process.terminate()
            process.wait()
        parts = in_process(posts[0], Path(folder) / "apart.sqlite3")
    body = report(http, parts, len(posts[0]))
    print(body)
    if args.docs:
        write_section(SECTION, f"python -m benchmarks.service_overhead --windows {args.windows} --docs", body)


if __name__ == "__main__":
    main()
