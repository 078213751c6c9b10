"""ema fleet's throughput against Ray workers, start-up apart from steady state, beside the warm service's.

An archive of 80 windows from 8 actuators (0.5 s, 10 kHz, realistic noise) goes through
``ema.cli.fleet.run_fleet`` with 1 worker and with every core (2 here), each on a fresh local Ray:

- **end to end**: the archive's windows per second with Ray's start-up included, as ``ema fleet`` pays it;
- **steady state**: the same archive again on the Ray already up and warm, in windows per core-second
  (windows per second over the cores the workers hold): the cost that matters over a large archive;
- beside them, in the same run, a warm ``ema serve`` answering the same windows one after another, in
  windows per CPU-second of the service process (``/proc``), its every thread counted.

The projection: 100 aircraft x 2 elevator EMAs x a window every 20 s over 10 flight hours = 360 000 windows a
day. Figures are compared within one run (this machine's speed drifts ~2x from day to day).

    python -m benchmarks.fleet_scaling [--windows 80] [--docs]
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from pathlib import Path

import httpx

from benchmarks.real_time import cpu_seconds
from benchmarks.service_overhead import free_port, serve
from ema.cli.fleet import run_fleet
from ema.cli.report import write_section
from ema.estimate.config import PipelineConfig
from ema.model.params import HealthParams
from ema.model.runtime import available_cores
from ema.model.synthetic import synthetic_window
from ema.model.window import Window, window_to_dict

FLEET_DAY = 100 * 2 * (10 * 3600 // 20)  # windows a day
ACTUATORS = 8


def archive(n: int, tag: str = "") -> list[Window]:
    return [
        synthetic_window(
            HealthParams.single(), seed=i, actuator_id=f"tail-{i % ACTUATORS}/elevator", window_id=f"w{i}{tag}"
        )
        for i in range(n)
    ]


def timed(windows: list[Window], workers: int, folder: Path) -> tuple[float, float]:
    """(windows per second with Ray's start-up included, windows per core-second at steady state)."""
    import ray

    config = PipelineConfig()
    started = time.perf_counter()
    run_fleet(windows, folder / f"first-{workers}.csv", config=config, workers=workers, address=None, threads=1)
    end_to_end = len(windows) / (time.perf_counter() - started)
    again = [w.__class__(**{**w.__dict__, "window_id": f"{w.window_id}-again"}) for w in windows]
    started = time.perf_counter()
    run_fleet(again, folder / f"again-{workers}.csv", config=config, workers=workers, address=None, threads=1)
    steady = len(windows) / (time.perf_counter() - started) / workers
    ray.shutdown()
    return end_to_end, steady


def service_per_cpu_second(windows: list[Window], folder: Path) -> float:
    """Windows per CPU-second of a warm ``ema serve`` answering ``windows`` one after another."""
    port = free_port()
    process = serve(folder / "service.sqlite3", port)
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=120.0) as client:
            warm = window_to_dict(windows[0]) | {"window_id": "warm"}
            client.post("/v1/estimate", content=json.dumps(warm), headers={"Content-Type": "application/json"})
            before = cpu_seconds(process.pid)
            for window in windows:
                body = json.dumps(window_to_dict(window) | {"window_id": f"{window.window_id}-service"})
                client.post("/v1/estimate", content=body, headers={"Content-Type": "application/json"})
            return len(windows) / (cpu_seconds(process.pid) - before)
    finally:
        process.terminate()
        process.wait(timeout=30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=80)
    parser.add_argument("--docs", action="store_true")
    args = parser.parse_args()
    windows = archive(args.windows)
    cores = available_cores()
    with tempfile.TemporaryDirectory() as folder:
        rows = {workers: timed(windows, workers, Path(folder)) for workers in sorted({1, 2, cores})}
        service = service_per_cpu_second(windows, Path(folder))
    one = rows[1][0]
    lines = [
        f"| {w} | {end:.2f} | {end / one:.2f}x | {steady:.2f} | {steady * w:.2f} |" for w, (end, steady) in rows.items()
    ]
    best = max(steady for _, steady in rows.values())
    body = "\n".join(
        [
            f"{args.windows} windows from {ACTUATORS} actuators (0.5 s at 10 kHz, realistic noise), default pipeline "
            f"sizes, on {cores} cores; each worker is one core (a task reserves and pins one thread); a fresh local "
            "Ray per row. *End to end* includes Ray's start-up, as `ema fleet` pays it; *steady state* is the same "
            "archive again on the Ray already up.",
            "",
            "| workers | end to end, windows/s | vs 1 worker | steady state, windows per core-second "
            "| steady, windows/s |",
            "|---:|---:|---:|---:|---:|",
            *lines,
            "",
            f"The warm service, same windows, same run: **{service:.2f} windows per CPU-second** of its process "
            f"(every thread counted), against the fleet's {best:.2f} windows per core-second.",
            "",
            f"Projection: a fleet-day of {FLEET_DAY:,} windows (100 aircraft x 2 EMAs x a window every 20 s over 10 "
            f"flight hours) needs {FLEET_DAY / 86_400:.1f} windows/s: at {best:.2f} windows per core-second, "
            f"**{math.ceil(FLEET_DAY / 86_400 / best)} cores** working around the clock.",
        ]
    )
    print(body)
    if args.docs:
        write_section("Fleet throughput (Ray)", "python -m benchmarks.fleet_scaling --docs", body)


if __name__ == "__main__":
    main()
