from __future__ import annotations

from fastapi import APIRouter, Request

from service.schemas import HealthOut

router = APIRouter(tags=["health"])


@router.get("/healthz", response_model=HealthOut)
def healthz(request: Request) -> HealthOut:
    """Up; ``warm`` once the kernels are compiled (or loaded from cache) and a pipeline has run."""
    runner = request.app.state.runner
    return HealthOut(
        status="ok",
        warm=request.app.state.warm.is_set(),
        running=runner.running,
        queued=runner.queued,
        max_queue=runner.max_queue,
    )
