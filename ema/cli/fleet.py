"""``ema fleet``: an archive of windows through the pipeline on Ray workers, streamed into a results CSV.

Ray schedules (no home-made scheduler): each window is a task that reserves and pins its own
thread budget (one thread by default: a worker is a core, so throughput grows with workers),
results are written as they complete (``ray.wait``), the CSV is
the checkpoint (a rerun skips what it holds, so a crash never duplicates a window), and the same
rows can go into a service's SQLite history (idempotent as well). Without Ray and with one
worker the archive is processed in this process, one window after another. A window that lacks
what other windows of its actuator read (its flight's sensor zero, where it moved one way or read its
own less precisely; J_M, where it could not tell a heavier rotor from a weaker motor) is answered again
at the end with what they read (``ema.estimate.history``), as the service answers it from its history. A
window of a named flight is written once its flight's windows are answered (a recording's pieces come
together), one that could not tell J_M at the end of the run.
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ema.cli.results import ResultsWriter, done_windows, row_of
from ema.estimate.config import PipelineConfig
from ema.model.window import Window, window_to_dict

IN_FLIGHT_PER_WORKER = 2  # tasks queued per worker: enough to keep it busy, few enough to stop quickly
NODE_LOSSES = 3  # a window whose task died with its node this often (past Ray's retries) fails the run


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
        print(
            f"[{self.done}/{self.total}] {row['window_id']}: {'refused' if row.get('error') else 'ok'}  "
            f"{rate:.2f} windows/s, {(self.total - self.done) / rate:.0f} s left",
            file=sys.stderr,
        )


Job = tuple[Window, dict[str, Any] | None]  # a window and what other windows of its actuator read (HistoryReadings)
Answer = tuple[Window, dict]  # a window and its ema-estimate/1 document (or {"error": ...})


@dataclass(frozen=True)
class Documents:
    """The actuators' ema-actuator/1 documents a run reads its windows with (by actuator_id; the rest with
    ``default``, the thesis's where none is given), and the versions a history stored them under."""

    by_actuator: dict[str, Any] = field(default_factory=dict)  # actuator_id -> ema.model.actuator.ActuatorDocument
    default: Any = None  # an Actuator, or None: the thesis's (the answer then says so)
    versions: dict[str, int] = field(default_factory=dict)

    def task_arguments(self, window: Window) -> tuple[dict[str, Any] | None, int | None]:
        """(the document as JSON, its version) for ``window``'s task (None: the default,
        ``ema.model.actuator.THESIS``)."""
        document = self.by_actuator.get(window.actuator_id, self.default)
        if document is None:
            return None, None
        return document.model_dump(mode="json", by_alias=True), self.versions.get(window.actuator_id)


def _in_process(jobs: list[Job], config: PipelineConfig, threads: int, documents: Documents) -> Iterator[Answer]:
    from ema.kinds.remote import estimate_document

    for window, history in jobs:
        actuator, version = documents.task_arguments(window)
        yield (
            window,
            estimate_document(window_to_dict(window), config.model_dump(), threads, history, actuator, version),
        )


def _on_ray(
    jobs: list[Job], config: PipelineConfig, workers: int, threads: int, address: str | None, documents: Documents
) -> Iterator[Answer]:
    """Each job's answer as Ray returns it. A task lost with its node (past Ray's own retries) is submitted
    again, up to ``NODE_LOSSES`` times: a node that dies mid-run loses no window, and each is answered once."""
    import ray

    from ema.kinds.remote import connect, ray_task

    connect(address, workers * threads)
    task = ray_task(threads)
    pending: dict[Any, Job] = {}
    losses: dict[str, int] = {}
    queue = list(reversed(jobs))
    while queue or pending:
        while queue and len(pending) < IN_FLIGHT_PER_WORKER * workers:
            window, history = job = queue.pop()
            actuator, version = documents.task_arguments(window)
            reference = task.remote(window_to_dict(window), config.model_dump(), threads, history, actuator, version)
            pending[reference] = job
        ready, _ = ray.wait(list(pending), num_returns=1)
        for reference in ready:
            job = pending.pop(reference)
            try:
                answer = ray.get(reference)
            except (ray.exceptions.WorkerCrashedError, ray.exceptions.NodeDiedError, ray.exceptions.ObjectLostError):
                key = job[0].window_id
                losses[key] = losses.get(key, 0) + 1
                if losses[key] > NODE_LOSSES:
                    raise
                queue.append(job)
                continue
            yield job[0], answer


@dataclass
class _Readings:
    """What the run's windows read that others may lack (``ema.estimate.history``): sensor zeros by (actuator,
    flight), J_M readings by actuator, in the order answered; indexed so that each lookup reads one flight."""

    zeros: dict[tuple[str, str | None], list[Any]] = field(default_factory=dict)
    inertias: dict[str, list[Any]] = field(default_factory=dict)

    def add(self, window: Window, answer: dict[str, Any]) -> None:
        from ema.estimate.documents.window import WindowInfo

        info = WindowInfo.model_validate(answer["window"])
        if info.sensor_zero is not None and window.flight_id is not None:
            self.zeros.setdefault((window.actuator_id, window.flight_id), []).append(info.sensor_zero)
        if info.inertia_read is not None:
            self.inertias.setdefault(window.actuator_id, []).append(info.inertia_read)

    def lacked(self, window: Window, answer: dict[str, Any]) -> dict[str, Any] | None:
        """What the run's other windows lend this one that it lacks (``ema.estimate.history.wanted``), as JSON; or
        None."""
        from ema.estimate.documents.window import WindowInfo
        from ema.estimate.history import lent, wanted

        flight = self.zeros.get((window.actuator_id, window.flight_id), [])
        others = lent((z for z in flight if z.window_id != window.window_id), self.inertias.get(window.actuator_id, []))
        lacking = wanted(WindowInfo.model_validate(answer["window"]), others)
        return None if lacking is None else lacking.model_dump()


def _with_history(
    windows: list[Window],
    first: Iterator[Answer],
    again: Callable[[list[Job]], Iterator[Answer]],
) -> Iterator[Answer]:
    """The answers of ``first`` (one per window of ``windows``), each given out once what other windows of its
    actuator read is known: a window of a named flight once its flight's windows are answered (a recording's
    pieces come together), one that could not tell J_M once the run's are. A window that lacks what they
    read (``_Readings.lacked``) is answered ``again`` with it at the end, as the service reads it from its
    history."""
    unanswered = Counter((w.actuator_id, w.flight_id) for w in windows)
    readings = _Readings()
    held: list[Answer] = []  # until their flight is answered
    at_end: list[Answer] = []  # could not tell J_M: until the run is answered
    jobs: list[Job] = []

    def settled(window: Window, answer: dict) -> Iterator[Answer]:
        history = readings.lacked(window, answer)
        if history is None:
            yield window, answer
        else:
            jobs.append((window, history))

    for window, answer in first:
        unanswered[(window.actuator_id, window.flight_id)] -= 1
        if "error" in answer:
            yield window, answer
            continue
        readings.add(window, answer)
        (at_end if answer["window"].get("inertia_undecided") else held).append((window, answer))
        waiting: list[Answer] = []
        for w, a in held:
            if w.flight_id is not None and unanswered[(w.actuator_id, w.flight_id)] > 0:
                waiting.append((w, a))
            else:
                yield from settled(w, a)
        held = waiting
    for w, a in held + at_end:
        yield from settled(w, a)
    yield from again(jobs)


def run_fleet(
    windows: list[Window],
    out: Path,
    *,
    config: PipelineConfig,
    workers: int,
    address: str | None,
    threads: int = 1,
    database: str | Path | None = None,
    documents: Documents = Documents(),
) -> dict[str, Any]:
    """Every window of ``windows`` not yet in ``out``, on ``workers`` Ray workers of ``threads`` threads each
    (in-process with one worker and no Ray), each read with its actuator's document; with a ``database``, the
    documents go into that history first, and the answers record the versions they got there."""
    done = done_windows(out)
    todo = [w for w in windows if (w.actuator_id, w.window_id) not in done]
    progress = Progress(len(todo), started=time.perf_counter())
    in_process = workers == 1 and address is None and not ray_installed()
    store = _store(database)
    if store is not None:
        documents = _stored_documents(store, documents, {w.actuator_id for w in todo})

    def engine(jobs: list[Job]) -> Iterator[Answer]:
        if in_process:
            return _in_process(jobs, config, threads, documents)
        return _on_ray(jobs, config, workers, threads, address, documents)

    results = _with_history(todo, engine([(w, None) for w in todo]), engine)
    with ResultsWriter(out) as writer:
        for window, answer in results:
            row = row_of(window.actuator_id, window.window_id, answer)
            if store is not None and "error" not in answer:
                row = _stored(store, row, answer)
            writer.write(row)
            progress.tick(row)
    seconds = time.perf_counter() - progress.started
    return {
        "csv": str(out),
        "skipped": len(done & {(w.actuator_id, w.window_id) for w in windows}),
        "answered": progress.done - progress.refused,
        "refused": progress.refused,
        "seconds": seconds,
        "windows_per_s": progress.done / seconds if seconds > 0 else 0.0,
        "workers": workers,
        "engine": "in-process" if in_process else "ray",
    }


def check_engine(workers: int, address: str | None) -> None:
    """InputError naming the flag where it asks for Ray and Ray is not installed (before any file is written)."""
    if ray_installed() or (workers == 1 and address is None):
        return
    from ema.model.checks import InputError

    flag = "--ray-address" if address is not None else "--workers"
    raise InputError(
        flag, "needs Ray, an optional extra: pip install 'ema[fleet]' (or run one worker in this process: --workers 1)"
    )


def ray_installed() -> bool:
    import importlib.util

    return importlib.util.find_spec("ray") is not None


def _stored(store: Any, row: dict[str, Any], answer: dict[str, Any]) -> dict[str, Any]:
    """``row`` once its answer is in the history, or refused where the history holds another window's content
    under its window_id (``ema.history.errors.ConflictError``)."""
    from ema.estimate.documents import Estimate
    from ema.history.errors import ConflictError, WithdrawnError

    try:
        store.add(Estimate.model_validate(answer))
    except ConflictError as exc:
        return {"actuator_id": row["actuator_id"], "window_id": row["window_id"], "error": f"conflict: {exc}"}
    except WithdrawnError as exc:
        return {"actuator_id": row["actuator_id"], "window_id": row["window_id"], "error": f"withdrawn: {exc}"}
    return row


def _stored_documents(store: Any, documents: Documents, actuator_ids: set[str]) -> Documents:
    """``documents`` put into ``store`` (each actuator of the run with a document: its own or the default given),
    with the versions the history gave them."""
    versions = {}
    for actuator_id in sorted(actuator_ids):
        document = documents.by_actuator.get(actuator_id, documents.default)
        if document is not None:
            versions[actuator_id] = store.put_actuator(actuator_id, document).version
    return replace(documents, versions=versions)


def _store(database: str | Path | None) -> Any:
    """The history ``--database`` names (None: none); a setting that names none is bad input naming the flag."""
    if database is None:
        return None
    from ema.history.open import open_history, setting_error
    from ema.model.checks import InputError

    error = setting_error(str(database))
    if error is not None:
        raise InputError("--database", error)
    return open_history(database)
