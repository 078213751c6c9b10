"""Assemble the app: settings, store, job runner, warm-up, routers, error handlers."""

from __future__ import annotations

import logging
import threading
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

import numba
import torch
from fastapi import Depends, FastAPI

from service import errors
from service.body_limit import BodyLimit
from service.config import Settings, get_settings
from service.deps import require_api_key
from service.jobs import JobRunner
from service.routes import actuators, calibrate, estimate, health
from service.store import EstimateStore
from service.warmup import warm_up

log = logging.getLogger("ema.service")


def create_app(settings: Settings | None = None) -> FastAPI:
    settings = settings or get_settings()

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        # One pipeline at a time uses every core: Numba's and torch's pools each get them all,
        # and never run at once (the runner has one slot), so they do not oversubscribe.
        # Numba's thread count is per calling thread, so it is set in the worker thread itself.
        threads = min(settings.threads, numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
        torch.set_num_threads(threads)
        app.state.store = EstimateStore(settings.database)
        app.state.runner = JobRunner(
            settings.max_queue, settings.queue_timeout_s, initializer=lambda: numba.set_num_threads(threads)
        )
        if settings.warm_up:
            await app.state.runner.run(warm_up)
            log.info("kernels warm")
        app.state.warm.set()
        yield
        app.state.runner.shutdown()
        app.state.store.close()

    app = FastAPI(title="ema", version="0.1.0", lifespan=lifespan)
    app.state.settings = settings
    app.state.warm = threading.Event()
    errors.install(app)
    app.add_middleware(BodyLimit, max_bytes=settings.max_body_bytes)
    app.include_router(health.router)
    protected = [Depends(require_api_key)]
    app.include_router(estimate.router, dependencies=protected)
    app.include_router(actuators.router, dependencies=protected)
    app.include_router(calibrate.router, dependencies=protected)
    return app


__all__ = ["create_app"]
