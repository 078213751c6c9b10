"""ema fleet end to end, as a user waits for it, with 1 worker and with every core (2 here), beside the service.

An archive of 80 windows from 8 actuators (0.5 s, 10 kHz, realistic noise) is written as files, and the
``ema fleet`` command runs on it as a user types it (a fresh process, ``--json``), with 1 worker (in this
process) and with local worker processes, alternately, ``--repeats`` times each:

- **end to end**: the command's wall time, from its start to its exit, and the speed-up over 1 worker;
- **how it splits**: start-up (to the first answer: reading the archive, starting and warming the workers),
  windows, and the rate of the windows phase per worker (the cost that matters over a large archive);
- beside them, in the same run, a warm ``ema serve`` answering the same windows one after another, in
  windows per CPU-second of the service process (``/proc``), its every thread counted.

The projection: 100 aircraft x 2 elevator EMAs x a window every 20 s over 10 flight hours = 360 000 windows a
day. Figures are compared within one run (this machine's speed drifts ~2x from day to day).

    python -m benchmarks.fleet_scaling [--windows 80] [--repeats 3] [--docs]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import tempfile
from pathlib import Path

import httpx

from benchmarks.as_user import run_ema
from benchmarks.real_time import cpu_seconds
from benchmarks.service_overhead import free_port, serve
from ema.cli.benchmark_docs import typed_command, write_section
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.params import HealthParams
from ema.model.runtime import available_cores
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


def written(windows: list[Window], folder: Path) -> Path:
    """The archive as a folder of ema-window/1 files, as an export would leave it."""
    archive_folder = folder / "archive"
    archive_folder.mkdir()
    for window in windows:
        (archive_folder / f"{window.window_id}.json").write_text(json.dumps(window_to_dict(window)))
    return archive_folder


def timed(archive_folder: Path, workers: int, out: Path) -> tuple[float, dict[str, float]]:
    """(the command's wall time in s, its phases) for ``ema fleet`` with ``workers`` workers, a fresh output."""
    out.unlink(missing_ok=True)
    wall, answer = run_ema("fleet", str(archive_folder), "--out", str(out), "--workers", str(workers))
    return wall, answer["phases_s"]


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
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--docs", action="store_true")
    args = parser.parse_args()
    windows = archive(args.windows)
    cores = available_cores()
    counts = sorted({1, 2, cores})
    runs: dict[int, list[tuple[float, dict[str, float]]]] = {w: [] for w in counts}
    with tempfile.TemporaryDirectory() as folder:
        archive_folder = written(windows, Path(folder))
        for _ in range(args.repeats):  # alternately: a drift of the machine's speed reaches every count alike
            for workers in counts:
                runs[workers].append(timed(archive_folder, workers, Path(folder) / "results.csv"))
        service = service_per_cpu_second(windows, Path(folder))
    body = report(runs, service, n_windows=args.windows, cores=cores)
    print(body)
    if args.docs:
        write_section("Fleet throughput (ema fleet, end to end)", typed_command(), body)


def report(runs: dict[int, list[tuple[float, dict[str, float]]]], service: float, *, n_windows: int, cores: int) -> str:
    """The table: per worker count, the median wall time and phases over the repeats, the speed-up over 1."""
    median = {w: statistics.median(wall for wall, _ in r) for w, r in runs.items()}
    lines = []
    for workers, r in runs.items():
        start_up = statistics.median(p["start-up"] for _, p in r)
        phase = statistics.median(p["windows"] for _, p in r)
        spread = f"{min(wall for wall, _ in r):.1f}-{max(wall for wall, _ in r):.1f}"
        lines.append(
            f"| {workers} | {median[workers]:.1f} ({spread}) | {median[1] / median[workers]:.2f}x | {start_up:.1f} "
            f"| {phase:.1f} | {n_windows / phase / workers:.2f} |"
        )
    best = max(n_windows / statistics.median(p["windows"] for _, p in r) / w for w, r in runs.items())
    return "\n".join(
        [
            f"{n_windows} windows from {ACTUATORS} actuators (0.5 s at 10 kHz, realistic noise, one JSON file each), "
            f"default pipeline sizes, on {cores} cores: `ema fleet ARCHIVE --out X.csv --workers N --json` run as "
            f"a user runs it, {len(next(iter(runs.values())))} times per worker count, alternately; medians, the "
            "wall's range in brackets. One worker runs in the command's process; more are local processes, each "
            "a core (a task pins one thread).",
            "",
            "| workers | wall, s | vs 1 worker | start-up, s | windows, s | windows per worker-second |",
            "|---:|---:|---:|---:|---:|---:|",
            *lines,
            "",
            f"The warm service, same windows, same run: **{service:.2f} windows per CPU-second** of its process "
            f"(every thread counted), against the fleet's {best:.2f} windows per worker-second.",
            "",
            f"Projection: a fleet-day of {FLEET_DAY:,} windows (100 aircraft x 2 EMAs x a window every 20 s over 10 "
            f"flight hours) needs {FLEET_DAY / 86_400:.1f} windows/s: at {best:.2f} windows per worker-second, "
            f"**{_cores(math.ceil(FLEET_DAY / 86_400 / best))}** working around the clock.",
        ]
    )


def _cores(count: int) -> str:
    return f"{count} core" if count == 1 else f"{count} cores"


if __name__ == "__main__":
    main()
