"""Shared request dependencies: settings, the store, the job runner, a request's pipeline sizes."""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import Annotated

from fastapi import Depends, Request
from starlette.concurrency import run_in_threadpool

from ema.estimate.config import PipelineConfig, validated
from ema.model.actuator import THESIS, Actuator
from ema.model.checks import InputError
from ema.prognosis.documents import Prognosis
from ema.prognosis.prognose import prognose
from ema.service.config import Settings
from ema.service.jobs import CancelledError, JobRunner
from ema.service.store import EstimateStore


def get_settings(request: Request) -> Settings:
    settings: Settings = request.app.state.settings
    return settings


def get_store(request: Request) -> EstimateStore:
    store: EstimateStore = request.app.state.store
    return store


def get_runner(request: Request) -> JobRunner:
    runner: JobRunner = request.app.state.runner
    return runner


SettingsDep = Annotated[Settings, Depends(get_settings)]
StoreDep = Annotated[EstimateStore, Depends(get_store)]
RunnerDep = Annotated[JobRunner, Depends(get_runner)]

CEILINGS = {"n_simulations": "max_simulations", "n_timesteps": "max_timesteps", "hidden_units": "max_hidden_units"}


def request_config(settings: Settings, **overrides: int | None) -> PipelineConfig:
    """The service's pipeline sizes with a request's overrides, each within the service's ceiling."""
    given = {name: value for name, value in overrides.items() if value is not None}
    for name, value in given.items():
        ceiling = getattr(settings, CEILINGS.get(name, ""), None)
        if ceiling is not None and value > ceiling:
            raise InputError(f"query.{name}", f"{value} exceeds this service's limit of {ceiling}")
    return validated(PipelineConfig, {**settings.pipeline.model_dump(), **given}, prefix="query.")


async def actuator_of(store: EstimateStore, actuator_id: str) -> tuple[Actuator, int | None]:
    """The actuator's latest stored document and its version, or the default (``ema.model.actuator.THESIS``, no
    version) where it has none: its windows are then read with the default, and their answers say so."""
    stored = await run_in_threadpool(store.get_actuator, actuator_id)
    return (THESIS, None) if stored is None else (stored.document, stored.version)


class Prognoses:
    """The latest prognoses, each kept until its actuator stores another window or document (a prognosis with its
    backtest takes seconds; a fleet page asks for every actuator's)."""

    def __init__(self, size: int = 512) -> None:
        self.size = size
        self._kept: OrderedDict[tuple[str, int, int | None, int | None], Prognosis] = OrderedDict()

    def get(self, key: tuple[str, int, int | None, int | None]) -> Prognosis | None:
        found = self._kept.get(key)
        if found is not None:
            self._kept.move_to_end(key)
        return found

    def put(self, key: tuple[str, int, int | None, int | None], prognosis: Prognosis) -> None:
        self._kept[key] = prognosis
        while len(self._kept) > self.size:
            self._kept.popitem(last=False)


async def prognosis_of(prognoses: Prognoses, store: EstimateStore, actuator_id: str) -> Prognosis:
    """The actuator's prognosis over its stored estimates, to its document's thresholds (kept while they stand)."""
    current, _ = await run_in_threadpool(store.history, actuator_id)
    document, version = await actuator_of(store, actuator_id)
    key = (actuator_id, len(current), current[-1].id if current else None, version)
    found = prognoses.get(key)
    if found is None:
        found = await run_in_threadpool(prognose, actuator_id, current, document)
        prognoses.put(key, found)
    return found


def stopper(cancel: threading.Event) -> Callable[[str], None]:
    """An ``on_stage`` callback that stops the job at its next stage once ``cancel`` is set."""

    def on_stage(_: str) -> None:
        if cancel.is_set():
            raise CancelledError("the client left; stopped before the next stage")

    return on_stage
