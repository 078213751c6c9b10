"""The local worker processes of ``ema fleet --workers N``: a pool of processes forked from a fork server that has
loaded the pipeline's and the kernels' modules once (``ema.cli.fork_server``, its program: the collector set first,
as every ema process sets it), each warmed as it starts (its thread budget pinned, its kernels loaded:
``ema.kinds.remote.warm``).

This module imports nothing of ema's at its top: the command starts the fork server before it imports what reads
the archive, so that the server loads them while the driver is still loading its own modules and reading, on the
other core. The workers fork from that clean, single-purpose process (no thread of the driver's, nothing of a
window's run yet: the only threads there are the BLAS pool's, which stops itself at a fork), so no worker loads
them again; the driver, which only reads and writes, never loads it.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import multiprocessing.forkserver
import os
import signal
from collections import Counter
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ema.cli.workers import Answer, Documents, Job
    from ema.estimate.config import PipelineConfig

PRELOADED = ("ema.cli.fork_server",)  # the server loads the pipeline and the kernels' modules, its collector set first
IN_FLIGHT_PER_WORKER = 2  # tasks queued per worker: enough to keep it busy, few enough to stop quickly
NODE_LOSSES = 3  # a window whose task died with its process or node this often fails the run


class LocalWorkers:
    """A pool of local worker processes, each warmed as it starts (module docstring); start it first thing: its fork
    server starts loading then, and the processes fork from it at the first job. A process lost mid-run (killed)
    loses no window: its jobs go to a new pool, ``NODE_LOSSES`` times at most."""

    def __init__(self, workers: int, threads: int) -> None:
        self.workers, self.threads = workers, threads
        self.pool = self._started()

    def _started(self) -> ProcessPoolExecutor:
        context = multiprocessing.get_context("forkserver")  # never a fork of the driver, which may hold threads
        context.set_forkserver_preload(list(PRELOADED))
        multiprocessing.forkserver.ensure_running()  # loading now; a process's start waits for it
        return ProcessPoolExecutor(self.workers, mp_context=context, initializer=_warmed, initargs=(self.threads,))

    def answers(self, jobs: list[Job], config: PipelineConfig, documents: Documents) -> Iterator[Answer]:
        """Each job's (window, answer) as a process returns it, ``IN_FLIGHT_PER_WORKER`` jobs per process queued."""
        queue, losses = list(reversed(jobs)), Counter[str]()
        pending: dict[Future, Job] = {}
        while queue or pending:
            while queue and len(pending) < IN_FLIGHT_PER_WORKER * self.workers and not self.pool._broken:
                job = queue.pop()
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
        """The processes stopped once idle after their last answer (none was forked where the pool never had a job:
        nothing left to answer, or the archive could not be read), then the fork server (``_stop_fork_server``)."""
        self.pool.shutdown(wait=True, cancel_futures=True)
        _stop_fork_server()


def _stop_fork_server() -> None:
    """The fork server killed and forgotten (the next pool starts another): it holds nothing once its workers are
    gone, and its own exit would tear its modules down, which a caller reading the command's output
    through a pipe waits for (as a user waits for no loading that serves nothing)."""
    server: Any = multiprocessing.forkserver._forkserver  # private: the standard library offers no stop
    if server._forkserver_pid is not None:
        with contextlib.suppress(ProcessLookupError):
            os.kill(server._forkserver_pid, signal.SIGTERM)
        server._stop()


def _warmed(threads: int) -> None:
    """A local worker's initializer, ``ema.kinds.remote.warm``, imported in the worker: the driver that only reads
    and writes never loads the pipeline or the kernels (a second of a core the workers need at start-up)."""
    from ema.cli.lifeline import die_with_parent
    from ema.kinds.remote import warm

    die_with_parent()  # with the fork server, which dies with the command
    warm(threads)


def _answered(*arguments: Any) -> dict[str, Any]:
    """``ema.kinds.remote.estimate_json`` on a local worker, imported there (``_warmed``)."""
    from ema.kinds.remote import estimate_json

    return estimate_json(*arguments)
