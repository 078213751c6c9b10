from __future__ import annotations

from typing import Any

from fastapi import APIRouter
from starlette.concurrency import run_in_threadpool

from service.deps import StoreDep
from service.schemas import HistoryOut
from service.store import trend

router = APIRouter(prefix="/v1/actuators", tags=["actuators"])


@router.get("/{actuator_id:path}/estimates", response_model=HistoryOut, response_model_by_alias=True)
async def history(actuator_id: str, store: StoreDep) -> dict[str, Any]:
    """Every stored estimate of the actuator, oldest first, and each parameter's drift trend."""
    estimates = await run_in_threadpool(store.history, actuator_id)
    return {"actuator_id": actuator_id, "estimates": estimates, "trend": trend(estimates)}
