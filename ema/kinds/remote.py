"""One window as a self-contained task: what a worker process runs (a local pool's or a Ray cluster's), and how a
process is warmed before its first.

The task carries the window as its ``ema-window/1`` JSON and the config as a dict, pins its own
thread budget (``ema.estimate.thread_budget``) before it computes, and returns the ``ema-estimate/1``
document as JSON-able data, or the refusal as ``{"error": {"field", "message"}}`` (an ``InputError``'s
parts, so that it crosses a process boundary typed, never as a sentence to parse back). Ray is imported only here, and
only when asked for: it is an optional extra (``pip install -e '.[fleet]'``).
"""

from __future__ import annotations

import gc
from typing import Any

from ema.estimate import thread_budget
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import Estimate
from ema.kinds import borrowed_document, estimate, warm_up
from ema.model.actuator import THESIS, ActuatorDocument, actuator_from_dict
from ema.model.checks import InputError
from ema.model.document import Document
from ema.model.window import Window, window_from_dict, window_to_dict


def estimate_json(
    window: dict[str, Any],
    config: dict[str, Any],
    threads: int,
    history: dict[str, Any] | None = None,
    document: dict[str, Any] | None = None,
    version: int | None = None,
) -> dict[str, Any]:
    """The estimate of one window as a JSON-able dict, or {"error": {"field", "message"}} for a window refused;
    ``history``: what other windows of the actuator read, ``document``: its ema-actuator/1 document and
    ``version`` (none: the default, ``ema.model.actuator.THESIS``; ``ema.kinds.estimate``)."""
    thread_budget.configure(threads)
    try:
        actuator = THESIS if document is None else actuator_from_dict(document)
        known = None if history is None else borrowed_document(actuator, history)
        result = estimate(
            window_from_dict(window), PipelineConfig(**config), actuator=actuator, version=version, history=known
        )
    except InputError as exc:
        return {"error": {"field": exc.field, "message": exc.message}}
    return result.model_dump(mode="json", by_alias=True)


def warm(threads: int) -> None:
    """A worker process made ready before its first window: its thread budget pinned, its kernels loaded, and what
    it loaded (the pipeline's modules, the kernels: it lives as long as the process) never walked by the cyclic
    collector again, at a window's collections or at the process's end."""
    thread_budget.configure(threads)
    warm_up((THESIS.kind,))  # the default document's kind; a window of another kind loads its own at its first
    gc.freeze()


def ray_task(threads: int) -> Any:
    """``estimate_json`` as a Ray remote function that reserves ``threads`` CPUs per task."""
    import ray

    return ray.remote(num_cpus=threads, max_retries=2)(estimate_json)


def connect(address: str | None, cpus: int) -> None:
    """Join the cluster at ``address`` ("auto" or host:port), or start a local Ray with ``cpus`` CPUs."""
    import ray

    if ray.is_initialized():
        return
    if address is None:
        ray.init(num_cpus=cpus, include_dashboard=False, log_to_driver=False, configure_logging=False)
    else:
        ray.init(address=address, log_to_driver=False, configure_logging=False)


def estimate_on_ray(
    window: Window,
    config: PipelineConfig,
    threads: int,
    history: Document | None = None,
    actuator: ActuatorDocument = THESIS,
    version: int | None = None,
) -> Estimate:
    """``estimate_window`` run as a Ray task (the service's EMA_BACKEND=ray); blocks this thread until done."""
    import ray

    known = None if history is None else history.model_dump()
    document = None if actuator is THESIS else actuator.model_dump(mode="json", by_alias=True)
    task = ray_task(threads).remote(window_to_dict(window), config.model_dump(), threads, known, document, version)
    answer = ray.get(task)
    if "error" in answer:
        raise InputError(**answer["error"])
    return Estimate.model_validate(answer)
