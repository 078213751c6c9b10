"""Request bodies -> documents, off the event loop, and the request budget.

The body arrives as bytes (already bounded in size by ``service.guard``) and is parsed and
validated in a worker thread by the contract's own model (pydantic-core yields the GIL often
enough that /healthz answers within ~70 ms while 100 MB are parsed). Errors name the field. The
budget is then checked before any work: a window's duration, and the simulation work
(simulations × seconds of window), each against the service's settings.
"""

from __future__ import annotations

from typing import TypeVar

from pydantic import BaseModel, ValidationError
from starlette.concurrency import run_in_threadpool

from service.config import Settings
from sim.checks import InputError, from_validation
from sim.window import Window
from training.config import PipelineConfig

Model = TypeVar("Model", bound=BaseModel)


def _parse(model: type[Model], body: bytes) -> Model:
    if not body:
        raise InputError("body", "is empty: expected a JSON document")
    try:
        return model.model_validate_json(body)
    except ValidationError as exc:
        first = exc.errors()[0]
        if first["type"] == "json_invalid":
            raise InputError("body", f"is not valid JSON ({first['msg']})") from None
        raise from_validation(exc) from None


async def parse(model: type[Model], body: bytes) -> Model:
    """``body`` validated as ``model`` in a worker thread; InputError naming the field otherwise."""
    return await run_in_threadpool(_parse, model, body)


def check_budget(window: Window, config: PipelineConfig, settings: Settings, field: str = "signals") -> None:
    """Refuse, naming the field and the limit, a window longer or a request costlier than the settings allow."""
    if window.duration_s > settings.max_window_s:
        limit = f"{settings.max_window_s:g} s (EMA_MAX_WINDOW_S)"
        raise InputError(field, f"the window lasts {window.duration_s:g} s; this service's limit is {limit}: cut it")
    work = config.total_simulations * window.duration_s
    if work > settings.max_simulated_s:
        raise InputError("query.n_simulations", f"{config.total_simulations} simulations of a {window.duration_s:g} s "
                         f"window are {work:g} simulated seconds; this service's limit is {settings.max_simulated_s:g} "
                         "(EMA_MAX_SIMULATED_S)")  # fmt: skip
