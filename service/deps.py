"""Shared request dependencies: settings, the store, the job runner, the API key check."""

from __future__ import annotations

import secrets
from dataclasses import replace
from typing import Annotated, Any

from fastapi import Depends, Header, HTTPException, Request, status

from service.config import Settings
from service.jobs import JobRunner
from service.store import EstimateStore
from training.pipeline import PipelineConfig


def get_settings(request: Request) -> Settings:
    settings: Settings = request.app.state.settings
    return settings


def get_store(request: Request) -> EstimateStore:
    store: EstimateStore = request.app.state.store
    return store


def get_runner(request: Request) -> JobRunner:
    runner: JobRunner = request.app.state.runner
    return runner


def require_api_key(
    settings: Annotated[Settings, Depends(get_settings)],
    x_api_key: Annotated[str | None, Header()] = None,
) -> None:
    """With ``EMA_API_KEY`` set, every /v1 request must carry it in X-API-Key."""
    if settings.api_key is None:
        return
    if x_api_key is None or not secrets.compare_digest(x_api_key, settings.api_key):
        raise HTTPException(status.HTTP_401_UNAUTHORIZED, "missing or wrong X-API-Key")


def pipeline_config(settings: Settings, **overrides: Any) -> PipelineConfig:
    """The pipeline sizes of this service, with a request's overrides (already bounds-checked)."""
    default = PipelineConfig(
        n_simulations=settings.n_simulations,
        n_timesteps=settings.n_timesteps,
        hidden_units=settings.hidden_units,
        members=settings.members,
        check_windows=settings.check_windows,
        seed=settings.seed,
    )
    return replace(default, **overrides)


SettingsDep = Annotated[Settings, Depends(get_settings)]
StoreDep = Annotated[EstimateStore, Depends(get_store)]
RunnerDep = Annotated[JobRunner, Depends(get_runner)]
