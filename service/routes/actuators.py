from __future__ import annotations

from fastapi import APIRouter
from starlette.concurrency import run_in_threadpool

from prognosis.documents import History, Prognosis
from prognosis.prognose import prognose
from service.deps import SettingsDep, StoreDep
from service.schemas import responses

router = APIRouter(prefix="/actuators", tags=["actuators"])


@router.get("/{actuator_id:path}/estimates", response_model=History, responses=responses(401))
async def history(actuator_id: str, store: StoreDep) -> History:
    """Every stored estimate of the actuator, oldest first, one per window."""
    current, legacy = await run_in_threadpool(store.history, actuator_id)
    return History(actuator_id=actuator_id, estimates=current, legacy=legacy)


@router.get("/{actuator_id:path}/prognosis", response_model=Prognosis, responses=responses(401))
async def prognosis(actuator_id: str, store: StoreDep, settings: SettingsDep) -> Prognosis:
    """Trend of FDJ, η_O and η_A and the remaining useful life to the service's thresholds (EMA_THRESHOLDS__*)."""
    current, _ = await run_in_threadpool(store.history, actuator_id)
    return await run_in_threadpool(prognose, actuator_id, current, settings.thresholds)
