"""Assemble the app: settings, store, job runner, warm-up, the guard, routers under the settings' prefix."""

from __future__ import annotations

import asyncio
import logging
import threading
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib.metadata import version
from typing import Any

from fastapi import FastAPI
from fastapi_offline import FastAPIOffline

from ema.estimate import runtime
from ema.model import runtime as sim_runtime
from ema.model.actuator import Actuator
from ema.model.window import WindowDocument
from ema.service import errors
from ema.service.config import Settings
from ema.service.deps import Prognoses
from ema.service.guard import Guard
from ema.service.jobs import JobRunner
from ema.service.routes import actuators, calibrate, estimate, health, ui
from ema.service.schemas import CalibrateIn
from ema.service.store import EstimateStore
from ema.service.warmup import warm_up

log = logging.getLogger("ema.service")
DESCRIPTION = """Onboard health monitor for an elevator EMA: one logged window in, FDJ, η_O, η_A out.

Budget per request (defaults; the operator's EMA_* settings may change them): a window of at most
10 s (EMA_MAX_WINDOW_S), simulations × window seconds at most 1500 (EMA_MAX_SIMULATED_S), a
calibration of at most 4 s of windows together (EMA_MAX_CALIBRATE_S), a body of at most 128 MB
(EMA_MAX_BODY_BYTES) that arrives within 60 s (EMA_BODY_TIMEOUT_S). Over it: 422 (413 for the
body, 408 for a late one) naming the limit. Writes are application/json only (else 415), never
from a web page of another origin (403). One job runs at a time; at most EMA_MAX_QUEUE wait; the
rest get 503 with Retry-After. Another body under a stored (actuator_id, window_id): 409."""


def _openapi(app: FastAPI) -> dict[str, Any]:
    """FastAPI's document, plus the schemas of the bodies the routes parse themselves."""
    if app.openapi_schema is None:
        from fastapi.openapi.utils import get_openapi

        schema = get_openapi(title=app.title, version=app.version, description=app.description, routes=app.routes)
        components = schema.setdefault("components", {}).setdefault("schemas", {})
        for model in (WindowDocument, CalibrateIn, Actuator):
            document = model.model_json_schema(ref_template="#/components/schemas/{model}", by_alias=True)
            components.update(document.pop("$defs", {}))
            components[model.__name__] = document
        app.openapi_schema = schema
    return app.openapi_schema


def create_app(settings: Settings) -> FastAPI:
    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        threads = runtime.configure(settings.threads)
        app.state.store = EstimateStore(settings.database)
        slots = settings.ray_jobs if settings.backend == "ray" else 1
        app.state.runner = JobRunner(settings.max_queue, settings.queue_timeout_s, slots, settings.max_uploads)
        if settings.backend == "ray":
            from ema.estimate.remote import connect

            connect(settings.ray_address, threads)
        if settings.warm_up:
            await asyncio.get_running_loop().run_in_executor(app.state.runner._executor, warm_up)
            log.info("kernels warm")
        app.state.warm.set()
        yield
        app.state.runner.shutdown()
        sim_runtime.shutdown()
        app.state.store.close()

    app = FastAPIOffline(title="ema", version=version("ema"), description=DESCRIPTION, lifespan=lifespan)
    app.state.settings = settings
    app.state.warm = threading.Event()
    app.state.prognoses = Prognoses()
    app.openapi = lambda: _openapi(app)  # type: ignore[method-assign]
    errors.install(app)
    app.add_middleware(
        Guard,
        key=settings.key_bytes(),
        prefix=settings.api_prefix,
        max_body_bytes=settings.max_body_bytes,
        body_timeout_s=settings.body_timeout_s,
        allowed_origins=settings.allowed_origins,
    )
    app.include_router(health.router)
    app.include_router(ui.router)
    for router in (estimate.router, actuators.router, calibrate.router):
        app.include_router(router, prefix=settings.api_prefix)
    return app
