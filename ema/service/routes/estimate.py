from __future__ import annotations

import threading
from collections.abc import Callable
from functools import partial
from typing import Annotated

from fastapi import APIRouter, Query, Request
from starlette.concurrency import run_in_threadpool

from ema import kinds
from ema.estimate.config import PipelineConfig, bounds
from ema.estimate.documents import Estimate
from ema.history.open import History
from ema.model.window import Window, WindowDocument
from ema.prognosis.documents import Stored
from ema.service.config import Settings
from ema.service.deps import RunnerDep, SettingsDep, StoreDep, actuator_of, request_config, stopper
from ema.service.parsing import check_budget, read_body
from ema.service.schemas import json_body, responses

router = APIRouter(tags=["estimate"])


def _query(name: str, what: str) -> object:
    low, high = bounds(name)
    return Query(ge=low, le=high, description=f"{what} (default and ceiling: the service's settings)")


def _window_and_digest(document: WindowDocument) -> tuple[Window, str]:
    window = document.to_window()
    return window, window.content_sha256()


@router.post(
    "/estimate",
    response_model=Stored,
    response_model_by_alias=True,
    responses=responses(401, 409, 410, 413, 415, 422, 503),
    openapi_extra=json_body(WindowDocument, "one ema-window/1 window"),
)
async def estimate(
    request: Request,
    *,
    settings: SettingsDep,
    store: StoreDep,
    runner: RunnerDep,
    n_simulations: Annotated[int | None, _query("n_simulations", "simulations to train on")] = None,
    n_timesteps: Annotated[int | None, _query("n_timesteps", "network input timesteps")] = None,
    hidden_units: Annotated[int | None, _query("hidden_units", "hidden neurons")] = None,
    seed: Annotated[int | None, _query("seed", "seed of the dataset and the training")] = None,
) -> Stored:
    """Estimate FDJ, η_O, η_A (FSJ where the window shows it) of one window; store and answer.

    A window already stored for its (actuator_id, window_id) is answered from the history
    (``replay: true``) without recomputing; other content under a stored key is another window: 409; a window an
    operator withdrew stays withdrawn: 410, naming the withdrawal.
    What the stored windows of the actuator read that this one may not (its ``flight_id``'s sensor
    zero, the actuator's J_M: ``ema.estimate.history``) is read with it, and so is the actuator's latest
    ``ema-actuator/1`` document (the default where it has none; the answer records which).
    Budget: the window's duration and its simulation work (simulations × seconds) are limited by the
    service's settings; over it, 422 naming the limit.
    """
    window, digest = await read_body(request, runner, WindowDocument, _window_and_digest)
    sizes = {"n_simulations": n_simulations, "n_timesteps": n_timesteps, "hidden_units": hidden_units, "seed": seed}
    key, found = (
        (window.actuator_id, window.window_id),
        partial(store.get, window.actuator_id, window.window_id, digest),
    )
    with runner.admit() as ticket:
        while (running := runner.sharing.running(key)) is not None:
            await running.wait(request.is_disconnected)  # the same window posted meanwhile: its answer is ours
            if (stored := await run_in_threadpool(found)) is not None:
                return stored
        with runner.sharing.lead(key) as shared:
            if (stored := await run_in_threadpool(found)) is not None:
                return stored
            config = request_config(settings, **sizes)
            check_budget(window, config, settings)
            await run_in_threadpool(store.probe)  # a history that cannot take the answer refuses before any work
            job = await _job(settings, store, window, config, ticket.cancel)
            result = await runner.run(ticket, shared.gone(request.is_disconnected), job)
            stored = await run_in_threadpool(store.add, result)  # committed (fsync) before the answer leaves
            await run_in_threadpool(store.probe)  # the file it went to is still the history: else no 200
            request.app.state.keeper.poke()  # its actuator's fleet line is out of date
            return stored


async def _job(
    settings: Settings, store: History, window: Window, config: PipelineConfig, cancel: threading.Event
) -> Callable[[], Estimate]:
    """The pipeline run for ``window``: in this process or on Ray, with what the history lends it."""
    history = await run_in_threadpool(store.readings, window.actuator_id, window.flight_id)
    actuator, version = await actuator_of(store, window.actuator_id)
    if settings.backend == "ray":
        from ema.kinds.remote import estimate_on_ray

        return partial(estimate_on_ray, window, config, 1, history, actuator, version)
    return partial(
        kinds.estimate, window, config, actuator=actuator, version=version, on_stage=stopper(cancel), history=history
    )
