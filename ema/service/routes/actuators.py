"""An actuator: its ``ema-actuator/1`` document (versioned), its stored estimates, its prognosis."""

from __future__ import annotations

from fastapi import APIRouter, Request
from starlette.concurrency import run_in_threadpool

from ema.model.actuator import Actuator
from ema.prognosis.documents import History, Prognosis, StoredActuator
from ema.service.deps import RunnerDep, StoreDep, prognosis_of
from ema.service.parsing import read_body
from ema.service.schemas import json_body, responses

router = APIRouter(prefix="/actuators", tags=["actuators"])


@router.get("/{actuator_id:path}/estimates", response_model=History, responses=responses(401))
async def history(actuator_id: str, store: StoreDep) -> History:
    """Every stored estimate of the actuator, oldest first, one per window."""
    current, legacy = await run_in_threadpool(store.history, actuator_id)
    return History(actuator_id=actuator_id, estimates=current, legacy=legacy)


@router.get("/{actuator_id:path}/prognosis", response_model=Prognosis, responses=responses(401))
async def prognosis(actuator_id: str, request: Request, store: StoreDep) -> Prognosis:
    """Trend of FDJ, η_O and η_A and the remaining useful life to the thresholds of the actuator's document
    (the default actuator's where it has none), with its backtest."""
    return await prognosis_of(request.app.state.prognoses, store, actuator_id)


@router.put(
    "/{actuator_id:path}",
    response_model=StoredActuator,
    response_model_by_alias=True,
    responses=responses(401, 403, 413, 415, 422, 503),
    openapi_extra=json_body(Actuator, "the actuator's ema-actuator/1 document"),
)
async def put_actuator(actuator_id: str, request: Request, store: StoreDep, runner: RunnerDep) -> StoredActuator:
    """Store the actuator's document as its next version: its windows are read with it from now on (those
    stored keep the version they were read with). The same document again stores nothing new."""
    document = await read_body(request, runner, Actuator, lambda d: d)
    return await run_in_threadpool(store.put_actuator, actuator_id, document)


@router.get(
    "/{actuator_id:path}", response_model=StoredActuator, response_model_by_alias=True, responses=responses(401, 404)
)
async def get_actuator(actuator_id: str, store: StoreDep) -> StoredActuator:
    """The actuator's latest document; 404 where none was stored (its windows are read with the default)."""
    from ema.service.errors import NotStoredError

    stored = await run_in_threadpool(store.get_actuator, actuator_id)
    if stored is None:
        raise NotStoredError(actuator_id)
    return stored
