"""Where a window's task runs in ``ema fleet``: the engines, each yielding (window, answer) as answers come.

- ``in_process``: one window after another in this process (one worker);
- ``ema.cli.pool.LocalWorkers``: a pool of local processes (the standard library's executor), its fork server
  started first thing and loading the pipeline while the driver reads the archive;
- ``on_ray``: a Ray cluster's workers (``--ray-address``).

Each window is a task that pins its own thread budget (one thread by default: a worker is a core, so throughput
grows with workers). A task lost with its process or node is submitted again, ``NODE_LOSSES`` times at most: no
window is lost and none is answered twice.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from ema.cli.pool import IN_FLIGHT_PER_WORKER, NODE_LOSSES
from ema.estimate.config import PipelineConfig
from ema.model.window import Window, window_to_dict

Job = tuple[Window, dict[str, Any] | None]  # a window, and what its actuator's other windows lend it as JSON
Answer = tuple[Window, dict]  # a window and its ema-estimate/1 document (or {"error": ...})


@dataclass(frozen=True)
class Documents:
    """The actuators' ema-actuator/1 documents a run reads its windows with (by actuator_id; the rest with
    ``default``, the thesis's where none is given), and the versions a history stored them under."""

    by_actuator: dict[str, Any] = field(default_factory=dict)  # actuator_id -> ema.model.actuator.ActuatorDocument
    default: Any = None  # an Actuator, or None: the thesis's (the answer then says so)
    versions: dict[str, int] = field(default_factory=dict)

    def of(self, actuator_id: str) -> Any:
        """The document ``actuator_id``'s windows are read with: its own, else ``default`` (None: the thesis's)."""
        return self.by_actuator.get(actuator_id, self.default)

    def task_arguments(self, window: Window) -> tuple[dict[str, Any] | None, int | None]:
        """(the document as JSON, its version) for ``window``'s task (None: the default,
        ``ema.model.actuator.THESIS``)."""
        document = self.of(window.actuator_id)
        if document is None:
            return None, None
        return document.model_dump(mode="json", by_alias=True), self.versions.get(window.actuator_id)

    def task(self, job: Job, config: PipelineConfig, threads: int) -> tuple[Any, ...]:
        """``ema.kinds.remote.estimate_json``'s arguments for ``job``: all of it JSON-able, for any process."""
        window, history = job
        document, version = self.task_arguments(window)
        return window_to_dict(window), config.model_dump(), threads, history, document, version


def in_process(jobs: list[Job], config: PipelineConfig, threads: int, documents: Documents) -> Iterator[Answer]:
    """Each job's answer from this process, one after another (the pipeline and the kernels loaded only for a job)."""
    if not jobs:
        return
    from ema.kinds.remote import estimate_json

    for job in jobs:
        yield job[0], estimate_json(*documents.task(job, config, threads))


def on_ray(
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
            job = queue.pop()
            pending[task.remote(*documents.task(job, config, threads))] = job
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
