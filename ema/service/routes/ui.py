"""The operator's view: ``/ui`` (the fleet, a page at a time) and ``/ui/actuators/{id}`` (one actuator)."""

from __future__ import annotations

import hashlib
import math
from typing import Annotated, Literal

from fastapi import APIRouter, Query, Request, Response
from fastapi.responses import HTMLResponse, RedirectResponse
from starlette.concurrency import run_in_threadpool

from ema.history.open import History
from ema.service.deps import ActuatorId, SettingsDep, StoreDep, is_stored, prognosis_now
from ema.service.pages import actuator_page, fleet_page, missing_page
from ema.service.share import Share
from ema.service.view import FleetView

router = APIRouter(tags=["ui"], include_in_schema=False)
StatusFilter = Literal["due", "watch", "prognosis failed", "not enough history", "healthy"]


@router.get("/")
async def root() -> RedirectResponse:
    """The service's front page is the operator's view."""
    return RedirectResponse("/ui", status_code=307)


@router.get("/ui", response_class=HTMLResponse)
async def fleet(
    *,
    request: Request,
    settings: SettingsDep,
    status: Annotated[StatusFilter | None, Query()] = None,
    tail: Annotated[str | None, Query(max_length=200, description="actuator ids starting with it")] = None,
    page: Annotated[int, Query(ge=1, le=1_000_000)] = 1,
) -> Response:
    """The actuators most urgent first, ``ui_page_size`` a page, filtered by status and by tail; in the view's
    share of the machine (``ema.service.share``), from the lines as last read (``FleetView``)."""
    share: Share = request.app.state.view_share
    async with share.turn():
        return await run_in_threadpool(_fleet_page, request, settings.ui_page_size, status, tail, page)


def _fleet_page(request: Request, size: int, status: str | None, tail: str | None, page: int) -> Response:
    view: FleetView = request.app.state.view
    found = view.lines()
    lines = [
        line
        for line in found.lines
        if (status is None or line.status == status) and (not tail or line.actuator_id.startswith(tail))
    ]
    pages = max(1, math.ceil(len(lines) / size))
    shown = lines[(min(page, pages) - 1) * size : min(page, pages) * size]
    body = fleet_page(
        shown, page=min(page, pages), pages=pages, total=len(lines), pending=found.pending, status=status, tail=tail
    )
    return revalidated(request, body)


def revalidated(request: Request, body: str) -> Response:
    """``body`` with its ETag (its content's digest), or 304 Not Modified where the browser holds that very page: a
    reload of an unchanged view sends nothing again. ``no-cache``: the browser asks each time, the fleet moves."""
    tag = '"' + hashlib.blake2b(body.encode(), digest_size=16).hexdigest() + '"'
    headers = {"ETag": tag, "Cache-Control": "no-cache"}
    if tag in [t.strip() for t in request.headers.get("if-none-match", "").split(",")]:
        return Response(status_code=304, headers=headers)
    return HTMLResponse(body, headers=headers)


@router.get("/ui/actuators/{actuator_id:path}", response_class=HTMLResponse)
async def actuator(actuator_id: ActuatorId, request: Request, store: StoreDep) -> HTMLResponse:
    """One actuator's plots, notes, backtest, calibrations and document, read and drawn in the view's share of the
    machine (``ema.service.share``), as the fleet's page is: a page never takes a job's place, however many viewers
    reload it; a 404 page where nothing of it is stored."""
    if not await is_stored(store, actuator_id):
        return HTMLResponse(missing_page(actuator_id), status_code=404)
    share: Share = request.app.state.view_share
    async with share.turn():
        page = await run_in_threadpool(_actuator_page, request, store, actuator_id)
    return HTMLResponse(page)


def _actuator_page(request: Request, store: History, actuator_id: str) -> str:
    prognosis, history = prognosis_now(request.app.state.prognoses, store, actuator_id)
    document, reports = store.get_actuator(actuator_id), store.calibrations(actuator_id)
    return actuator_page(actuator_id, history, prognosis, document, reports)
