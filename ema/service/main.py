"""Assemble the app: settings, store, job runner, warm-up, the guard, routers under the settings' prefix."""

from __future__ import annotations

import asyncio
import gc
import logging
import threading
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib.metadata import version
from typing import Any

from fastapi import FastAPI
from fastapi_offline import FastAPIOffline

from ema.estimate import thread_budget
from ema.history.open import open_history
from ema.kinds import warm_up
from ema.model import runtime as sim_runtime
from ema.model.actuator import ActuatorDocument, actuator_schema
from ema.model.window import WindowDocument
from ema.service import errors
from ema.service.config import Settings
from ema.service.deps import Prognoses
from ema.service.guard import BodyLimits, Guard
from ema.service.jobs import JobRunner
from ema.service.routes import actuators, calibrate, estimate, health, ui
from ema.service.schemas import CalibrateIn
from ema.service.share import Share
from ema.service.view import FleetView, LineKeeper

log = logging.getLogger("ema.service")


def description(settings: Settings) -> str:
    """The OpenAPI description: this service's own budget, read from its settings (never restated)."""
    return f"""Onboard health monitor for an electromechanical actuator: one logged window in, FDJ, η_O, η_A out.

Budget per request (EMA_* settings): a window of at most {settings.max_window_s:g} s (EMA_MAX_WINDOW_S),
simulations × window seconds at most {settings.max_simulated_s:g} (EMA_MAX_SIMULATED_S), a calibration of at
most {settings.max_calibrate_s:g} s of windows together (EMA_MAX_CALIBRATE_S), a body of at most
{settings.max_body_bytes} bytes (EMA_MAX_BODY_BYTES) that arrives within {settings.body_timeout_s:g} s
(EMA_BODY_TIMEOUT_S) and, after {settings.body_grace_s:g} s, at {settings.min_body_rate_bps:g} B/s or more. Over
it: 422 (413 for the body, 408 for a late or slow one) naming the limit. Writes are uncompressed
application/json only (else 415), never from a web page of another origin (403). One job runs at a time; at
most {settings.max_queue} wait (EMA_MAX_QUEUE); the rest get 503 with Retry-After. Another body under a stored
(actuator_id, window_id): 409. A history that cannot store an answer: 503 naming why, before any work."""


def _openapi(app: FastAPI) -> dict[str, Any]:
    """FastAPI's document, plus the schemas of the bodies the routes parse themselves."""
    if app.openapi_schema is None:
        from fastapi.openapi.utils import get_openapi

        schema = get_openapi(title=app.title, version=app.version, description=app.description, routes=app.routes)
        components = schema.setdefault("components", {}).setdefault("schemas", {})
        template = "#/components/schemas/{model}"
        for model in (WindowDocument, CalibrateIn):
            document = model.model_json_schema(ref_template=template, by_alias=True)
            components.update(document.pop("$defs", {}))
            components[model.__name__] = document
        document = actuator_schema(ref_template=template)  # one kind's document, by its kind
        components.update(document.pop("$defs", {}))
        components[ActuatorDocument.__name__] = document
        app.openapi_schema = schema
    return app.openapi_schema


def create_app(settings: Settings) -> FastAPI:
    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        threads = thread_budget.configure(settings.threads)
        app.state.store = open_history(settings.database, settings.min_free_bytes)
        slots = settings.ray_jobs if settings.backend == "ray" else 1
        app.state.runner = JobRunner(settings.max_queue, settings.queue_timeout_s, slots)
        app.state.view = FleetView(app.state.store)
        app.state.view_share = Share(settings.ui_share)
        app.state.keeper = LineKeeper(app.state.store, app.state.runner, app.state.view)
        if settings.backend == "ray":
            from ema.kinds.remote import connect

            connect(settings.ray_address, threads)
        if settings.warm_up:
            await asyncio.get_running_loop().run_in_executor(app.state.runner._executor, warm_up)
            gc.freeze()  # what the warm-up loaded lives as long as the service: no full collection walks it again
            log.info("kernels warm")
        app.state.warm.set()
        app.state.keeper.start()
        yield
        app.state.keeper.stop()
        app.state.runner.shutdown()
        sim_runtime.shutdown()
        app.state.store.close()

    app = FastAPIOffline(title="ema", version=version("ema"), description=description(settings), lifespan=lifespan)
    app.state.settings = settings
    app.state.warm = threading.Event()
    app.state.prognoses = Prognoses()
    app.openapi = lambda: _openapi(app)  # type: ignore[method-assign]
    errors.install(app)
    limits = BodyLimits.of(settings)
    app.add_middleware(
        Guard,
        key=settings.key_bytes(),
        prefix=settings.api_prefix,
        limits=limits,
        allowed_origins=settings.allowed_origins,
    )
    app.include_router(health.router)
    app.include_router(ui.router)
    for router in (estimate.router, actuators.router, calibrate.router):
        app.include_router(router, prefix=settings.api_prefix)
    return app
