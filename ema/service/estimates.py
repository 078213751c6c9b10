"""What ``POST /v1/estimate`` does once its window is parsed: the route parses, calls ``answered`` and answers.

A window already stored under its key is answered from the history; the same window posted while it runs waits
for that run's answer; otherwise the budget is checked, the history probed (a history that cannot take the
answer refuses before any work), the pipeline run in this process or on Ray with what the history lends it,
and the answer committed before it leaves. The fleet view's line of the actuator is then out of date.
"""

from __future__ import annotations

import threading
from collections.abc import Awaitable, Callable
from functools import partial

from starlette.concurrency import run_in_threadpool

from ema import kinds
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import Estimate
from ema.history.open import History
from ema.model.window import Window
from ema.prognosis.documents import Stored
from ema.service.config import Settings
from ema.service.deps import actuator_of, request_config, stopper, stored_kind
from ema.service.jobs import JobRunner
from ema.service.parsing import check_budget
from ema.service.view import LineKeeper


async def answered(
    window: Window,
    digest: str,
    sizes: dict[str, int | None],
    *,
    settings: Settings,
    store: History,
    runner: JobRunner,
    keeper: LineKeeper,
    gone: Callable[[], Awaitable[bool]],
) -> Stored:
    """The stored answer to ``window`` (its content's ``digest``), computed at the request's ``sizes`` unless the
    history holds it or a run of the same window is under way; ``gone`` says the client left."""
    key = (window.actuator_id, window.window_id)
    found = partial(store.get, window.actuator_id, window.window_id, digest)
    with runner.admit() as ticket:
        while (running := runner.sharing.running(key)) is not None:
            await running.wait(gone)  # the same window posted meanwhile: its answer is ours
            if (stored := await run_in_threadpool(found)) is not None:
                return stored
        with runner.sharing.lead(key) as shared:
            if (stored := await run_in_threadpool(found)) is not None:
                return stored
            config = request_config(settings, **sizes)
            check_budget(window, config, settings)
            await run_in_threadpool(store.probe)  # a history that cannot take the answer refuses before any work
            job = await _job(settings, store, window, config, ticket.cancel)
            result = await runner.run(ticket, shared.gone(gone), job)
            stored = await run_in_threadpool(store.add, result)  # committed (fsync) before the answer leaves
            await run_in_threadpool(store.probe)  # the file it went to is still the history: else no 200
            keeper.poke()  # its actuator's fleet line is out of date
            return stored


async def _job(
    settings: Settings, store: History, window: Window, config: PipelineConfig, cancel: threading.Event
) -> Callable[[], Estimate]:
    """The pipeline run for ``window``: in this process or on Ray, with what the history lends it."""
    lent = await run_in_threadpool(store.lent_to, window.actuator_id, window.flight_id)
    actuator, version = await actuator_of(store, window.actuator_id)
    stored_kind([window], actuator, version, listed=False)
    history = kinds.other_windows_lent(actuator, lent)
    if settings.backend == "ray":
        from ema.kinds.remote import estimate_on_ray

        return partial(estimate_on_ray, window, config, 1, history, actuator, version)
    return partial(
        kinds.estimate, window, config, actuator=actuator, version=version, on_stage=stopper(cancel), history=history
    )
