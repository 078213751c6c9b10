"""``ema fleet``: an archive of windows through the pipeline on workers (``ema.cli.workers``), streamed into a
results CSV.

Results are written as they complete, the CSV is the checkpoint (a rerun skips what it holds, so a crash never
duplicates a window), and the same rows can go into a service's history (idempotent as well). A window that
lacks what other windows of its actuator read (its flight's sensor zero, where it moved one way or read its
own less precisely; J_M, where it could not tell a heavier rotor from a weaker motor) is answered again
at the end with what they read (``ema.kinds.rotary.other_windows``), as the service answers it from its history. A
window of a named flight is written once its flight's windows are answered (a recording's pieces come
together), one that could not tell J_M at the end of the run. The answer says how the wall time split:
start-up (from the command's start to the first answer), windows, and of those, writing rows.
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ema.cli.pool import LocalWorkers
from ema.cli.results import ResultsWriter, document_digest, done_windows, refused_under, row_of
from ema.cli.workers import Answer, Documents, Job, in_process, on_ray
from ema.estimate.config import PipelineConfig
from ema.model.window import Window


@dataclass
class Progress:
    total: int
    done: int = 0
    refused: int = 0
    started: float = 0.0
    first_at: float | None = None  # when the first answer came

    def tick(self, row: dict[str, Any]) -> None:
        self.done += 1
        self.refused += bool(row.get("error"))
        elapsed = time.perf_counter() - self.started
        rate = self.done / max(elapsed, 1e-9)
        verdict = f"refused: {str(row['error'])[:160]}" if row.get("error") else "ok"
        print(
            f"[{self.done}/{self.total}] {row['window_id']}: {verdict}  "
            f"{rate:.2f} windows/s, {(self.total - self.done) / rate:.0f} s left",
            file=sys.stderr,
        )


@dataclass
class _Readings:
    """What the run's windows lent others (``ema.kinds.lent_by``): by (actuator, flight) what each lent its flight's
    windows, with its window_id; by actuator what each lent every window; in the order answered, indexed so that each
    lookup reads one flight."""

    to_flights: dict[tuple[str, str | None], list[tuple[str, str]]] = field(default_factory=dict)
    to_actuators: dict[str, list[str]] = field(default_factory=dict)

    def add(self, window: Window, answer: dict[str, Any]) -> bool:
        """Keep what ``answer`` lends; whether the window waits for the run's others (``waits_for_the_run``)."""
        from ema.estimate.documents.window_facts import window_info_from
        from ema.kinds import lent_by, waits_for_the_run

        info = window_info_from(answer["window"])
        lent = lent_by(info)
        if lent.to_flight is not None and window.flight_id is not None:
            flight = self.to_flights.setdefault((window.actuator_id, window.flight_id), [])
            flight.append((window.window_id, lent.to_flight))
        if lent.to_actuator is not None:
            self.to_actuators.setdefault(window.actuator_id, []).append(lent.to_actuator)
        return waits_for_the_run(info)

    def lacked(self, window: Window, answer: dict[str, Any], actuator: Any) -> dict[str, Any] | None:
        """What the run's other windows lend this one, read with ``actuator``'s document, that it lacks
        (``ema.kinds.lacking``), as JSON; or None."""
        from ema.estimate.documents.window_facts import window_info_from
        from ema.kinds import Borrowed, lacking, other_windows_lent
        from ema.model.actuator import THESIS

        flight = self.to_flights.get((window.actuator_id, window.flight_id), [])
        kept = Borrowed(
            from_flight=tuple(lent for window_id, lent in flight if window_id != window.window_id),
            from_actuator=tuple(self.to_actuators.get(window.actuator_id, [])),
        )
        others = other_windows_lent(actuator or THESIS, kept)  # None: the run reads it with the thesis's
        lacked = lacking(window, window_info_from(answer["window"]), others)
        return None if lacked is None else lacked.model_dump()


def _with_history(
    windows: list[Window],
    first: Iterator[Answer],
    again: Callable[[list[Job]], Iterator[Answer]],
    documents: Documents,
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
        history = readings.lacked(window, answer, documents.of(window.actuator_id))
        if history is None:
            yield window, answer
        else:
            jobs.append((window, history))

    for window, answer in first:
        unanswered[(window.actuator_id, window.flight_id)] -= 1
        if "error" in answer:
            yield window, answer
            continue
        (at_end if readings.add(window, answer) else held).append((window, answer))
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
    documents: Documents | None = None,
    pool: LocalWorkers | None = None,
    started: float | None = None,
    conflicts: dict[tuple[str, str], list[str]] | None = None,
) -> dict[str, Any]:
    """Every window of ``windows`` not yet in ``out``, on ``workers`` workers of ``threads`` threads each (a Ray
    cluster's with an ``address``, else a local pool: ``pool`` where one was started already, in this process with
    one worker), each read with its actuator's document; with a ``database``, the documents go into that history
    first, and the answers record the versions they got there. ``started``: when the command began (the phases
    the answer gives count from it). ``conflicts``: keys the archive holds in several files with different content
    (``ema.cli.logs.Log.conflicts``), each a refused row naming its files, once, none read."""
    began = time.perf_counter() if started is None else started
    documents = Documents() if documents is None else documents
    done, retried = done_windows(out), refused_since(out, documents)
    todo = [w for w in windows if (key := (w.actuator_id, w.window_id)) not in done or key in retried]
    progress = Progress(len(todo), started=time.perf_counter())
    conflicted = _conflict_rows(out, conflicts or {}, done)
    engine_name, pool = _engine(todo, workers=workers, threads=threads, address=address, pool=pool)
    store = _store(database)
    if store is not None:
        documents = _stored_documents(store, documents, {w.actuator_id for w in todo})

    def engine(jobs: list[Job]) -> Iterator[Answer]:
        if pool is not None:
            return pool.answers(jobs, config, documents)
        if address is None:
            return in_process(jobs, config, threads, documents)
        return on_ray(jobs, config, workers, threads, address, documents)

    try:
        answers = _with_history(todo, engine([(w, None) for w in todo]), engine, documents)
        writing = _written(answers, out, store, progress, documents)
    finally:
        if pool is not None:
            pool.close()
    skipped = len((done - retried) & {(w.actuator_id, w.window_id) for w in windows})
    return _summary(out, progress, skipped, conflicted, began=began, writing=writing, engine=(engine_name, workers))


def refused_since(out: Path, documents: Documents) -> set[tuple[str, str]]:
    """The windows ``out`` holds refused under a document that has changed since: read again."""
    refused = refused_under(out)
    return {key for key, digest in refused.items() if digest != document_digest(documents.of(key[0]))}


def _summary(
    out: Path, progress: Progress, skipped: int, conflicted: int, *, began: float, writing: float, engine: tuple
) -> dict[str, Any]:
    """What the run did: its counts, its rate, its engine, and how its wall time split (from ``began``)."""
    ended = time.perf_counter()
    return {
        "csv": str(out),
        "skipped": skipped,
        "answered": progress.done - progress.refused,
        "refused": progress.refused + conflicted,
        "seconds": ended - began,
        "windows_per_s": progress.done / (ended - began) if ended > began else 0.0,
        "workers": engine[1],
        "engine": engine[0],
        "phases_s": {
            "start-up": (progress.first_at or ended) - began,
            "windows": ended - (progress.first_at or ended),
            "writing": writing,
        },
    }


def _engine(
    todo: list[Window], *, workers: int, threads: int, address: str | None, pool: LocalWorkers | None
) -> tuple[str, LocalWorkers | None]:
    """(the engine's name, the local pool or None): Ray with an address; this process for one worker, for one
    window (nothing to share out), or where no window trains a network (``ema.kinds.learns``: milliseconds a window,
    less than a process's start-up), the pool started meanwhile stopped; else the local pool, started here if the
    command did not."""
    if address is not None:
        return "ray", pool
    if workers == 1:
        return "in-process", pool
    from ema.kinds import learns

    if len(todo) == 1:
        reason = "one window"
    elif todo and not any(learns(window) for window in todo):
        reason = "no window learns a network"
    else:
        return "local processes", LocalWorkers(workers, threads) if pool is None else pool
    if pool is not None:
        pool.close()
    return f"in-process: {reason}", None


def _conflict_rows(out: Path, conflicts: dict[tuple[str, str], list[str]], done: set[tuple[str, str]]) -> int:
    """A refused row for each conflicting key not in ``out`` yet, in the keys' order (the same file whatever the
    workers do); how many were written."""
    fresh = sorted(key for key in conflicts if key not in done)
    with ResultsWriter(out) as writer:
        for actuator_id, window_id in fresh:
            files = " and ".join(conflicts[(actuator_id, window_id)])
            error = f"conflict: {files} hold this window with different content: none is read (give each its own id)"
            writer.write({"actuator_id": actuator_id, "window_id": window_id, "error": error})
    return len(fresh)


def _written(results: Iterator[Answer], out: Path, store: Any, progress: Progress, documents: Documents) -> float:
    """Each answer into the CSV (and the history) as it comes, with the digest of the document it was read with;
    the seconds spent writing."""
    writing = 0.0
    with ResultsWriter(out) as writer:
        for window, answer in results:
            if progress.first_at is None:
                progress.first_at = time.perf_counter()
            begun = time.perf_counter()
            row = row_of(window.actuator_id, window.window_id, answer)
            row["document"] = document_digest(documents.of(window.actuator_id))
            if store is not None and "error" not in answer:
                row = _stored(store, row, answer)
            writer.write(row)
            writing += time.perf_counter() - begun
            progress.tick(row)
    return writing


def check_engine(workers: int, address: str | None) -> None:
    """InputError naming the flag where it asks for a Ray cluster and Ray is not installed (before any file is
    written): local workers need nothing beyond the standard library."""
    if address is None or ray_installed():
        return
    from ema.model.checks import InputError

    raise InputError(
        "--ray-address", "needs Ray, an optional extra: pip install 'ema[fleet]' (or run on local workers: --workers N)"
    )


def ray_installed() -> bool:
    import importlib.util

    return importlib.util.find_spec("ray") is not None


def _stored(store: Any, row: dict[str, Any], answer: dict[str, Any]) -> dict[str, Any]:
    """``row`` once its answer is in the history, or refused where the history holds another window's content
    under its window_id (``ema.history.refusals.ConflictError``)."""
    from ema.estimate.documents import Estimate
    from ema.history.refusals import ConflictError, WithdrawnError

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
        document = documents.of(actuator_id)
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
