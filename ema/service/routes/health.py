from __future__ import annotations

from fastapi import APIRouter, Request

from ema.service.schemas import HealthOut

router = APIRouter(tags=["health"])


@router.get("/healthz", response_model=HealthOut)
def healthz(request: Request) -> HealthOut:
    """Up; ``warm`` once the kernels are compiled (or loaded) and a pipeline has run; storage checked."""
    runner, store = request.app.state.runner, request.app.state.store
    storage_ok, storage = store.healthy()
    return HealthOut(
        status="ok" if storage_ok else "degraded",
        warm=request.app.state.warm.is_set(),
        running=runner.running,
        queued=runner.queued,
        max_queue=runner.max_queue,
        storage=storage,
    )
