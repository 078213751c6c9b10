"""The operator's view: ``/ui`` (the fleet) and ``/ui/actuators/{id}`` (one actuator), HTML from the service."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import HTMLResponse
from starlette.concurrency import run_in_threadpool

from ema.service.deps import StoreDep, actuator_of, prognosis_of
from ema.service.pages import Row, actuator_page, fleet_page, status_of

router = APIRouter(prefix="/ui", tags=["ui"], include_in_schema=False)


@router.get("", response_class=HTMLResponse)
async def fleet(request: Request, store: StoreDep) -> HTMLResponse:
    """Every actuator, most urgent first."""
    rows = []
    for actuator_id in await run_in_threadpool(store.actuator_ids):
        history, _ = await run_in_threadpool(store.history, actuator_id)
        prognosis = await prognosis_of(request.app.state.prognoses, store, actuator_id)
        actuator, _ = await actuator_of(store, actuator_id)
        latest = history[-1] if history else None
        status, soonest = status_of(latest, prognosis, actuator)
        rows.append(Row(actuator_id, latest, prognosis, actuator, status, soonest))
    return HTMLResponse(fleet_page(rows))


@router.get("/actuators/{actuator_id:path}", response_class=HTMLResponse)
async def actuator(actuator_id: str, request: Request, store: StoreDep) -> HTMLResponse:
    """One actuator's plots, notes, backtest, calibrations and document."""
    history, _ = await run_in_threadpool(store.history, actuator_id)
    prognosis = await prognosis_of(request.app.state.prognoses, store, actuator_id)
    document = await run_in_threadpool(store.get_actuator, actuator_id)
    actuator, _ = await actuator_of(store, actuator_id)
    reports = await run_in_threadpool(store.calibrations, actuator_id)
    return HTMLResponse(actuator_page(actuator_id, history, prognosis, document, actuator, reports))
