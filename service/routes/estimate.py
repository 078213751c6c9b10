from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Query
from starlette.concurrency import run_in_threadpool

from service.deps import RunnerDep, SettingsDep, StoreDep, pipeline_config
from service.errors import bounded
from service.schemas import EstimateOut, WindowIn
from service.windows import to_window
from sim.checks import InputError
from training.pipeline import estimate_window

router = APIRouter(prefix="/v1", tags=["estimate"])


@router.post("/estimate", response_model=EstimateOut, response_model_by_alias=True)
async def estimate(
    body: WindowIn,
    settings: SettingsDep,
    store: StoreDep,
    runner: RunnerDep,
    n_simulations: Annotated[int | None, Query(ge=20)] = None,
    n_timesteps: Annotated[int | None, Query(ge=10)] = None,
    hidden_units: Annotated[int | None, Query(ge=1)] = None,
    seed: Annotated[int | None, Query(ge=0)] = None,
) -> dict[str, Any]:
    """Simulate a Case-1B dataset for the window's own command, train, estimate; store and answer."""
    window = to_window(body)
    config = pipeline_config(
        settings,
        n_simulations=bounded("n_simulations", n_simulations, settings.n_simulations, settings.max_simulations),
        n_timesteps=bounded("n_timesteps", n_timesteps, settings.n_timesteps, settings.max_timesteps),
        hidden_units=bounded("hidden_units", hidden_units, settings.hidden_units, settings.max_hidden_units),
        seed=settings.seed if seed is None else seed,
    )
    if config.n_timesteps > window.n_samples:
        raise InputError("query.n_timesteps", f"{config.n_timesteps} exceeds the window's {window.n_samples} samples")
    result = await runner.run(estimate_window, window, config)
    return await run_in_threadpool(store.add, result)  # committed (fsync) before the answer leaves
