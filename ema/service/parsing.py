"""Request bodies -> documents, off the event loop, and the request budget.

The body arrives as bytes (bounded in size and time by ``ema.service.guard``) and is parsed and
validated on the job runner's one parsing thread by the contract's own model, before the request
takes a place in the queue (``ema.service.jobs``). Errors name the field. The
budget is then checked before any work: a window's duration, and the simulation work
(simulations × seconds of window), each against the service's settings.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Sequence
from typing import TypeVar

from fastapi import Request
from pydantic import BaseModel, TypeAdapter, ValidationError

from ema import kinds
from ema.estimate.config import PipelineConfig
from ema.model.checks import InputError, from_validation
from ema.model.kinds import KIND_NAMES
from ema.model.window import Window
from ema.service.config import Settings
from ema.service.jobs import JobRunner

Model = TypeVar("Model", bound=BaseModel)
T = TypeVar("T")


def _parse(model: type[Model] | TypeAdapter[Model], body: bytes) -> Model:
    if not body:
        raise InputError("body", "is empty: expected a JSON document")
    try:
        return model.validate_json(body) if isinstance(model, TypeAdapter) else model.model_validate_json(body)
    except ValidationError as exc:
        first = exc.errors()[0]
        if first["type"] == "json_invalid":
            raise InputError("body", f"is not valid JSON ({first['msg']})") from None
        raise from_validation(exc, tags=KIND_NAMES) from None  # an actuator's kind tags its document, no field


async def read_body(
    request: Request, runner: JobRunner, model: type[Model] | TypeAdapter[Model], then: Callable[[Model], T]
) -> T:
    """``then`` of the request's body validated as ``model`` (``JobRunner.receiving``: 503 at once when there is
    no room), both on the runner's parsing thread; InputError naming the field otherwise."""
    runner.receiving()
    chunks = [chunk async for chunk in request.stream()]  # joined on the parsing thread, not the event loop
    return await asyncio.get_running_loop().run_in_executor(
        runner.parser, lambda: then(_parse(model, b"".join(chunks)))
    )


def check_budget(window: Window, config: PipelineConfig, settings: Settings, field: str = "signals") -> None:
    """Refuse, naming the field and the limit, a window longer or a request costlier than the settings allow, by
    what its kind really does (``ema.kinds.cost``: a window read quasi-statically simulates nothing, a servo's
    simulations step at its controller's rate)."""
    cost = kinds.cost(window, config)
    if cost.window_s > settings.max_window_s:
        limit = f"{settings.max_window_s:g} s (EMA_MAX_WINDOW_S)"
        raise InputError(field, f"the window lasts {window.duration_s:g} s; this service's limit is {limit}: cut it")
    if cost.simulated_s > settings.max_simulated_s:
        raise InputError(
            "query.n_simulations",
            f"{config.total_simulations} simulations of this {window.duration_s:g} s window are "
            f"{cost.simulated_s:g} s of 1 µs simulation steps; this service's limit is "
            f"{settings.max_simulated_s:g} (EMA_MAX_SIMULATED_S)",
        )


def check_calibration_budget(windows: Sequence[Window], config: PipelineConfig, settings: Settings) -> None:
    """One budget for a whole calibration: its windows' count, the seconds of them its kind's loop grows with,
    and the simulation work of reading them all; over any, InputError naming the field and the limit."""
    if len(windows) > settings.max_calibrate_windows:
        raise InputError(
            "windows",
            f"{len(windows)} windows; this service's limit is "
            f"{settings.max_calibrate_windows} (EMA_MAX_CALIBRATE_WINDOWS)",
        )
    for i, window in enumerate(windows):
        check_budget(window, config, settings, field=f"windows.{i}.signals")
    cost = kinds.calibration_cost(windows, config)
    if cost.window_s > settings.max_calibrate_s:
        raise InputError(
            "windows",
            f"the windows last {cost.window_s:g} s together; this service's limit for one "
            f"calibration is {settings.max_calibrate_s:g} s (EMA_MAX_CALIBRATE_S)",
        )
    work = cost.simulated_s + sum(kinds.cost(window, config).simulated_s for window in windows)
    if work > settings.max_simulated_s:
        raise InputError(
            "windows",
            f"reading and calibrating these windows is {work:g} s of 1 µs simulation steps; this service's limit "
            f"is {settings.max_simulated_s:g} (EMA_MAX_SIMULATED_S)",
        )
