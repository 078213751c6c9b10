"""ema fleet's throughput against Ray workers, the overhead per task, and the cluster a fleet-day needs.

An archive of 40 windows from 4 actuators (0.5 s, 10 kHz, realistic noise) goes through
``ema.cli.fleet.run_fleet`` with 1 and then 2 workers, each a fresh local Ray started inside the
timing (start-up included, as ``ema fleet`` pays it), in one run. The overhead per task is a
no-op task's round trip on the same Ray. The projection: 100 aircraft x 2 elevator EMAs x a
window every 20 s over 10 flight hours = 360 000 windows a day.

    python -m benchmarks.fleet_scaling [--windows 40] [--docs]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from ema.cli.fleet import run_fleet
from ema.cli.report import write_section
from ema.estimate.config import PipelineConfig
from ema.model.params import HealthParams
from ema.model.runtime import available_cores
from ema.model.synthetic import synthetic_window
from ema.model.window import Window

FLEET_DAY = 100 * 2 * (10 * 3600 // 20)  # windows a day


def archive(n: int) -> list[Window]:
    return [
        synthetic_window(HealthParams.single(), seed=i, actuator_id=f"tail-{i % 4}/elevator", window_id=f"w{i}")
        for i in range(n)
    ]


def task_overhead_s(tasks: int = 200) -> float:
    """Mean wall time of a no-op Ray task, submitted and gathered in batches (Ray already running)."""
    import ray

    @ray.remote(num_cpus=1)
    def nothing() -> None:
        return None

    ray.get([nothing.remote() for _ in range(10)])
    started = time.perf_counter()
    ray.get([nothing.remote() for _ in range(tasks)])
    return (time.perf_counter() - started) / tasks


def timed(windows: list[Window], workers: int, folder: Path) -> tuple[float, float]:
    """(windows per second with Ray's start-up included, the no-op task overhead on that Ray)."""
    import ray

    started = time.perf_counter()
    run_fleet(
        windows, folder / f"results-{workers}.csv", config=PipelineConfig(), workers=workers, address=None, threads=1
    )
    rate = len(windows) / (time.perf_counter() - started)
    overhead = task_overhead_s()
    ray.shutdown()
    return rate, overhead


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=40)
    parser.add_argument("--docs", action="store_true")
    args = parser.parse_args()
    windows = archive(args.windows)
    with tempfile.TemporaryDirectory() as folder:
        (one, overhead_1), (two, overhead_2) = (timed(windows, w, Path(folder)) for w in (1, 2))
    cores = available_cores()
    per_core = two / cores
    needed = FLEET_DAY / 86_400 / per_core
    body = "\n".join(
        [
            f"{args.windows} windows from 4 actuators (0.5 s at 10 kHz, realistic noise), default pipeline sizes, a",
            f"fresh local Ray per row (start-up included), on {cores} cores; each worker is one core (a task reserves",
            "and pins one thread).",
            "",
            "| workers | windows/s | vs 1 worker | no-op task overhead |",
            "|---:|---:|---:|---:|",
            f"| 1 | {one:.2f} | 1.00x | {1e3 * overhead_1:.1f} ms |",
            f"| 2 | {two:.2f} | {two / one:.2f}x | {1e3 * overhead_2:.1f} ms |",
            "",
            f"Projection: a fleet-day of {FLEET_DAY:,} windows (100 aircraft x 2 EMAs x a window every 20 s over",
            f"10 flight hours) needs {FLEET_DAY / 86_400:.1f} windows/s; at {per_core:.2f} windows/s per core (2 "
            f"workers",
            f"here) that is **{needed:.0f} cores** working around the clock. What stops linear scaling: on this",
            "machine, the two cores are all there is (and Ray's own processes take a little of them); on a",
            "cluster each worker brings its own core, and the limits are the driver reading the archive and",
            "streaming results into one CSV (a few ms per task against ~1 s of work) and, past that, the archive's",
            "I/O: shard the archive across drivers well before that.",
        ]
    )
    print(body)
    if args.docs:
        write_section("Fleet throughput (Ray)", "python -m benchmarks.fleet_scaling --docs", body)


if __name__ == "__main__":
    main()
