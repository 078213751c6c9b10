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
from pydantic import BaseModel, ValidationError

from ema.estimate.config import PipelineConfig
from ema.model.checks import InputError, from_validation
from ema.model.window import Window
from ema.service.config import Settings
from ema.service.jobs import JobRunner

Model = TypeVar("Model", bound=BaseModel)
T = TypeVar("T")


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


async def read_body(request: Request, runner: JobRunner, model: type[Model], then: Callable[[Model], T]) -> T:
    """``then`` of the request's body validated as ``model`` (``JobRunner.receiving``: 503 at once when there is
    no room), both on the runner's parsing thread; InputError naming the field otherwise."""
    runner.receiving()
    chunks = [chunk async for chunk in request.stream()]  # joined on the parsing thread, not the event loop
    return await asyncio.get_running_loop().run_in_executor(
        runner.parser, lambda: then(_parse(model, b"".join(chunks)))
    )


def check_budget(window: Window, config: PipelineConfig, settings: Settings, field: str = "signals") -> None:
    """Refuse, naming the field and the limit, a window longer or a request costlier than the settings allow (a
    window read quasi-statically simulates nothing: its length costs only its samples, which the body limits)."""
    if window.kind == "linear" or not window.high_rate:
        return
    if window.duration_s > settings.max_window_s:
        limit = f"{settings.max_window_s:g} s (EMA_MAX_WINDOW_S)"
        raise InputError(field, f"the window lasts {window.duration_s:g} s; this service's limit is {limit}: cut it")
    work = config.total_simulations * window.duration_s
    if work > settings.max_simulated_s:
        raise InputError(
            "query.n_simulations",
            f"{config.total_simulations} simulations of a {window.duration_s:g} s "
            f"window are {work:g} simulated seconds; this service's limit is {settings.max_simulated_s:g} "
            "(EMA_MAX_SIMULATED_S)",
        )


def check_calibration_budget(windows: Sequence[Window], config: PipelineConfig, settings: Settings) -> None:
    """One budget for a whole calibration: its windows' count, their seconds together, and the simulation work
    of estimating them all; over any, InputError naming the field and the limit."""
    if len(windows) > settings.max_calibrate_windows:
        raise InputError(
            "windows",
            f"{len(windows)} windows; this service's limit is "
            f"{settings.max_calibrate_windows} (EMA_MAX_CALIBRATE_WINDOWS)",
        )
    for i, window in enumerate(windows):
        check_budget(window, config, settings, field=f"windows.{i}.signals")
    seconds = sum(window.duration_s for window in windows)
    if seconds > settings.max_calibrate_s:
        raise InputError(
            "windows",
            f"the windows last {seconds:g} s together; this service's limit for one "
            f"calibration is {settings.max_calibrate_s:g} s (EMA_MAX_CALIBRATE_S)",
        )
    work = config.total_simulations * seconds
    if work > settings.max_simulated_s:
        raise InputError(
            "windows",
            f"{config.total_simulations} simulations of {seconds:g} s of windows are "
            f"{work:g} simulated seconds; this service's limit is {settings.max_simulated_s:g} "
            "(EMA_MAX_SIMULATED_S)",
        )
