"""The actuators: their lines (status), ``ema-actuator/1`` documents (versioned), stored estimates (withdrawable),
and prognoses. An actuator with nothing stored is a 404 wherever its history is asked for."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query, Request
from starlette.concurrency import run_in_threadpool

from ema.model.actuator import ACTUATOR_DOCUMENT, ActuatorDocument
from ema.prognosis.documents import (
    ActuatorSummary,
    AnyPrognosis,
    EstimateHistory,
    Prognosis,
    StoredActuator,
    Withdrawal,
)
from ema.service.deps import ActuatorId, RunnerDep, StoreDep, is_stored, prognosis_now
from ema.service.errors import NotStoredError
from ema.service.parsing import read_body
from ema.service.schemas import json_body, responses
from ema.service.view import FleetView

router = APIRouter(prefix="/actuators", tags=["actuators"])


@router.get("", response_model=list[ActuatorSummary], responses=responses(401, 503))
async def actuators(request: Request) -> list[ActuatorSummary]:
    """Every actuator with a stored window or document, most urgent first, with its latest status (``/ui``'s
    lines; those the service's keeper has not brought up to date yet as they were last computed, pending)."""
    view: FleetView = request.app.state.view
    found = await run_in_threadpool(view.lines)
    return found.lines


async def _known(store: StoreDep, actuator_id: str) -> None:
    if not await is_stored(store, actuator_id):
        raise NotStoredError(actuator_id, "no window or document is stored for it")


@router.get("/{actuator_id:path}/estimates", response_model=EstimateHistory, responses=responses(401, 404, 422))
async def history(actuator_id: ActuatorId, store: StoreDep) -> EstimateHistory:
    """Every stored estimate of the actuator, oldest first, one per window; withdrawn ones apart."""
    await _known(store, actuator_id)
    current, legacy = await run_in_threadpool(store.history, actuator_id)
    withdrawn = await run_in_threadpool(store.withdrawals, actuator_id)
    return EstimateHistory(actuator_id=actuator_id, estimates=current, legacy=legacy, withdrawn=withdrawn)


@router.delete(
    "/{actuator_id:path}/estimates/{window_id:path}",
    response_model=Withdrawal,
    responses=responses(401, 403, 404, 422),
)
async def withdraw(
    actuator_id: ActuatorId,
    window_id: str,
    request: Request,
    store: StoreDep,
    reason: Annotated[str, Query(max_length=500, description="why, for the record")] = "none given",
) -> Withdrawal:
    """Take a stored window out of the actuator's history (a window that should never have been accepted):
    its trend and prognosis forget it; the record of it, and of why, stays."""
    found = await run_in_threadpool(store.withdraw, actuator_id, window_id, reason)
    if found is None:
        raise NotStoredError(actuator_id, f"no window {window_id!r} is stored for it")
    request.app.state.keeper.poke()
    return found


@router.get("/{actuator_id:path}/prognosis", response_model=AnyPrognosis, responses=responses(401, 404, 422, 503))
async def prognosis(actuator_id: ActuatorId, request: Request, store: StoreDep, runner: RunnerDep) -> Prognosis:
    """Trend of FDJ, η_O and η_A and the remaining useful life to the thresholds of the actuator's document
    (the default actuator's where it has none), with its backtest; computed as a job of the queue."""
    await _known(store, actuator_id)
    with runner.admit() as ticket:
        found, _ = await runner.run(
            ticket, request.is_disconnected, prognosis_now, request.app.state.prognoses, store, actuator_id
        )
    return found


@router.put(
    "/{actuator_id:path}",
    response_model=StoredActuator,
    response_model_by_alias=True,
    responses=responses(401, 403, 413, 415, 422, 503),
    openapi_extra=json_body(ActuatorDocument, "the actuator's ema-actuator/1 document"),
)
async def put_actuator(actuator_id: ActuatorId, request: Request, store: StoreDep, runner: RunnerDep) -> StoredActuator:
    """Store the actuator's document as its next version: its windows are read with it from now on (those
    stored keep the version they were read with). The same document again stores nothing new."""
    document = await read_body(request, runner, ACTUATOR_DOCUMENT, lambda d: d)
    await run_in_threadpool(store.probe)
    stored = await run_in_threadpool(store.put_actuator, actuator_id, document)
    request.app.state.keeper.poke()
    return stored


@router.get(
    "/{actuator_id:path}",
    response_model=StoredActuator,
    response_model_by_alias=True,
    responses=responses(401, 404, 422),
)
async def get_actuator(actuator_id: ActuatorId, store: StoreDep) -> StoredActuator:
    """The actuator's latest document; 404 where none was stored (its windows are read with the default)."""
    stored = await run_in_threadpool(store.get_actuator, actuator_id)
    if stored is None:
        raise NotStoredError(
            actuator_id,
            "no ema-actuator/1 document is stored for it: its windows are read with "
            "the default actuator (PUT one to this path)",
        )
    return stored
