"""``ema fleet``: an archive of windows through the pipeline on Ray workers, streamed into a results CSV.

Ray schedules (no home-made scheduler): each window is a task that reserves and pins its own
thread budget (one thread by default: a worker is a core, so throughput grows with workers),
results are written as they complete (``ray.wait``), the CSV is
the checkpoint (a rerun skips what it holds, so a crash never duplicates a window), and the same
rows can go into a service's SQLite history (idempotent as well). Without Ray and with one
worker the archive is processed in this process, one window after another. A window that lacks
what other windows of its actuator read (a one-way window, its flight's sensor zero; one that cannot
tell a heavier rotor from a weaker motor, J_M) is answered again at the end with what they read
(``training.history``), as the service answers it from its history.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from clients.results import ResultsWriter, done_windows, row_of
from sim.window import Window, window_to_dict
from training.config import PipelineConfig

IN_FLIGHT_PER_WORKER = 2  # tasks queued per worker: enough to keep it busy, few enough to stop quickly


@dataclass
class Progress:
    total: int
    done: int = 0
    refused: int = 0
    started: float = 0.0

    def tick(self, row: dict[str, Any]) -> None:
        self.done += 1
        self.refused += bool(row.get("error"))
        elapsed = time.perf_counter() - self.started
        rate = self.done / max(elapsed, 1e-9)
        print(f"[{self.done}/{self.total}] {row['window_id']}: {'refused' if row.get('error') else 'ok'}  "
              f"{rate:.2f} windows/s, {(self.total - self.done) / rate:.0f} s left", file=sys.stderr)  # fmt: skip


Job = tuple[Window, dict[str, Any] | None]  # a window and what other windows of its actuator read (HistoryReadings)


def _in_process(jobs: list[Job], config: PipelineConfig, threads: int) -> Iterator[tuple[Window, dict]]:
    from training.remote import estimate_document

    for window, history in jobs:
        yield window, estimate_document(window_to_dict(window), config.model_dump(), threads, history)


def _on_ray(jobs: list[Job], config: PipelineConfig, workers: int, threads: int,
            address: str | None) -> Iterator[tuple[Window, dict]]:  # fmt: skip
    import ray

    from training.remote import connect, ray_task

    connect(address, workers * threads)
    task = ray_task(threads)
    pending: dict[Any, Window] = {}
    queue = list(reversed(jobs))
    while queue or pending:
        while queue and len(pending) < IN_FLIGHT_PER_WORKER * workers:
            window, history = queue.pop()
            pending[task.remote(window_to_dict(window), config.model_dump(), threads, history)] = window
        ready, _ = ray.wait(list(pending), num_returns=1)
        for reference in ready:
            yield pending.pop(reference), ray.get(reference)


def _wants(window: Window, answer: dict[str, Any]) -> set[str]:
    """What the window could not read and other windows of its actuator may have: its flight's sensor zero
    (it moves one way), J_M (it could not tell a heavier rotor from a weaker motor)."""
    read = answer.get("window", {})
    wants = set()
    if window.flight_id is not None and read.get("sensor_zero") is None and read.get("sensor_zero_from") is None:
        wants.add("sensor_zero")
    if read.get("inertia_undecided"):
        wants.add("inertia")
    return wants if "error" not in answer else set()


def _with_history(
    first: Iterator[tuple[Window, dict]], again: Callable[[list[Job]], Iterator[tuple[Window, dict]]]
) -> Iterator[tuple[Window, dict]]:
    """The answers of ``first``; a window that wants what other windows of its actuator read (``_wants``)
    held back and, where they read it, answered ``again`` with it (``training.history``, as the service
    reads it from its history)."""
    from training.documents import WindowInfo
    from training.history import readings_of

    held: list[tuple[Window, dict]] = []
    read: dict[str, list[WindowInfo]] = {}
    for window, answer in first:
        if "error" not in answer:  # a window held back may still have read what another wants (a flight's zero)
            read.setdefault(window.actuator_id, []).append(WindowInfo.model_validate(answer["window"]))
        if _wants(window, answer):
            held.append((window, answer))
        else:
            yield window, answer
    jobs: list[Job] = []
    for window, answer in held:
        history = readings_of(read.get(window.actuator_id, []), window.flight_id)
        if any(getattr(history, name) is not None for name in _wants(window, answer)):
            jobs.append((window, history.model_dump()))
        else:
            yield window, answer
    yield from again(jobs)


def run_fleet(windows: list[Window], out: Path, config: PipelineConfig, workers: int, address: str | None,
              threads: int = 1, database: Path | None = None) -> dict[str, Any]:  # fmt: skip
    """Every window of ``windows`` not yet in ``out``, on ``workers`` Ray workers of ``threads`` threads each
    (in-process with one worker and no Ray)."""
    done = done_windows(out)
    todo = [w for w in windows if (w.actuator_id, w.window_id) not in done]
    progress = Progress(len(todo), started=time.perf_counter())
    in_process = workers == 1 and address is None and not ray_installed()

    def engine(jobs: list[Job]) -> Iterator[tuple[Window, dict]]:
        return _in_process(jobs, config, threads) if in_process else _on_ray(jobs, config, workers, threads, address)

    results = _with_history(engine([(w, None) for w in todo]), engine)
    store = _store(database)
    with ResultsWriter(out) as writer:
        for window, answer in results:
            row = row_of(window.actuator_id, window.window_id, answer)
            writer.write(row)
            if store is not None and "error" not in answer:
                from training.documents import Estimate

                store.add(Estimate.model_validate(answer))
            progress.tick(row)
    seconds = time.perf_counter() - progress.started
    return {"csv": str(out), "skipped": len(done & {(w.actuator_id, w.window_id) for w in windows}),
            "answered": progress.done - progress.refused, "refused": progress.refused, "seconds": seconds,
            "windows_per_s": progress.done / seconds if seconds > 0 else 0.0, "workers": workers,
            "engine": "in-process" if in_process else "ray"}  # fmt: skip


def ray_installed() -> bool:
    import importlib.util

    return importlib.util.find_spec("ray") is not None


def _store(database: Path | None) -> Any:
    if database is None:
        return None
    from service.store import EstimateStore

    return EstimateStore(database)
