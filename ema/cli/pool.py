"""The local worker processes of ``ema fleet --workers N``: a pool of spawned processes, each warmed as it starts
(its thread budget pinned, its kernels loaded: ``ema.kinds.remote.warm``).

This module imports nothing of ema's at its top: the command starts the pool before it imports what reads the
archive, so that the processes load torch and the kernels while the driver is still loading its own modules
(a worker's loading is the part of the run more workers cannot share). The driver, which only reads and
writes, never loads torch or the kernels.
"""

from __future__ import annotations

import multiprocessing
from collections import Counter
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ema.cli.workers import Answer, Documents, Job
    from ema.estimate.config import PipelineConfig

IN_FLIGHT_PER_WORKER = 2  # tasks queued per worker: enough to keep it busy, few enough to stop quickly
NODE_LOSSES = 3  # a window whose task died with its process or node this often fails the run


class LocalWorkers:
    """A pool of local worker processes, each warmed as it starts (module docstring); start it first thing. A
    process lost mid-run (killed) loses no window: its jobs go to a new pool, ``NODE_LOSSES`` times at most."""

    def __init__(self, workers: int, threads: int) -> None:
        self.workers, self.threads = workers, threads
        self.pool, self.used = self._started(), False

    def _started(self) -> ProcessPoolExecutor:
        context = multiprocessing.get_context("spawn")  # never a fork of a process that may hold threads
        pool = ProcessPoolExecutor(self.workers, mp_context=context, initializer=_warmed, initargs=(self.threads,))
        for _ in range(self.workers):
            pool.submit(int)  # a process per worker, warming now
        return pool

    def answers(self, jobs: list[Job], config: PipelineConfig, documents: Documents) -> Iterator[Answer]:
        """Each job's (window, answer) as a process returns it, ``IN_FLIGHT_PER_WORKER`` jobs per process queued."""
        queue, losses = list(reversed(jobs)), Counter[str]()
        pending: dict[Future, Job] = {}
        while queue or pending:
            while queue and len(pending) < IN_FLIGHT_PER_WORKER * self.workers and not self.pool._broken:
                job, self.used = queue.pop(), True
                pending[self.pool.submit(_answered, *documents.task(job, config, self.threads))] = job
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                job = pending.pop(future)
                try:
                    yield job[0], future.result()
                except BrokenProcessPool:
                    losses[job[0].window_id] += 1
                    if losses[job[0].window_id] > NODE_LOSSES:
                        raise
                    queue.append(job)
            if not pending and queue and self.pool._broken:  # a process died: the rest go to a new pool
                self.pool = self._started()

    def close(self) -> None:
        """The processes stopped: once idle after their last answer, or at once where they never had a job (nothing
        left to answer, or the archive could not be read): a user waits for no warming that serves nothing."""
        if not self.used:
            for process in list(self.pool._processes.values()):
                process.terminate()
        self.pool.shutdown(wait=True, cancel_futures=True)


def _warmed(threads: int) -> None:
    """A local worker's initializer, ``ema.kinds.remote.warm``, imported in the worker: the driver that only reads
    and writes never loads torch or the kernels (a second of a core the workers need at start-up)."""
    from ema.kinds.remote import warm

    warm(threads)


def _answered(*arguments: Any) -> dict[str, Any]:
    """``ema.kinds.remote.estimate_json`` on a local worker, imported there (``_warmed``)."""
    from ema.kinds.remote import estimate_json

    return estimate_json(*arguments)
