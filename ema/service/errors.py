"""Errors as HTTP answers: bad input 422 naming the field, another window under a stored key 409, nothing stored
404, overload 503 with Retry-After, a history that cannot take a write 503 naming why."""

from __future__ import annotations

from fastapi import FastAPI, Request, status
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.requests import ClientDisconnect

from ema.history.refusals import ConflictError, StorageError, VersionContentionError, WithdrawnError
from ema.model.checks import InputError
from ema.service.jobs import CancelledError, OverloadedError


def _location(field: str) -> list[str]:
    """``signals.current_a`` -> ["body", "signals", "current_a"]; query parameters keep "query"."""
    if field.startswith(("query.", "path.")):
        return field.split(".")
    if field == "body":
        return ["body"]
    return ["body", *field.split(".")]


async def input_error(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, InputError)
    detail = [{"loc": _location(exc.field), "msg": exc.message, "type": "value_error"}]
    return JSONResponse({"detail": detail}, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)


class NotStoredError(Exception):
    """Nothing is stored under the path's actuator_id (``why`` says what was asked for)."""

    def __init__(self, actuator_id: str, why: str) -> None:
        super().__init__(f"actuator {actuator_id!r}: {why}")


async def not_stored(request: Request, exc: Exception) -> JSONResponse:
    detail = [{"loc": ["path", "actuator_id"], "msg": str(exc), "type": "not_found"}]
    return JSONResponse({"detail": detail}, status_code=status.HTTP_404_NOT_FOUND)


async def conflict(request: Request, exc: Exception) -> JSONResponse:
    """Another window under a stored key: 409, never the stored window's answer."""
    assert isinstance(exc, ConflictError)
    detail = [{"loc": ["body", "window_id"], "msg": str(exc), "type": "conflict"}]
    return JSONResponse({"detail": detail}, status_code=status.HTTP_409_CONFLICT)


async def withdrawn(request: Request, exc: Exception) -> JSONResponse:
    """A withdrawn window posted again: 410, naming its withdrawal."""
    assert isinstance(exc, WithdrawnError)
    detail = [{"loc": ["body", "window_id"], "msg": str(exc), "type": "withdrawn"}]
    body = {"detail": detail, "withdrawal": exc.withdrawal.model_dump()}
    return JSONResponse(body, status_code=status.HTTP_410_GONE)


async def contended(request: Request, exc: Exception) -> JSONResponse:
    """Other writers of the actuator's document kept taking its version: 409, put it again."""
    detail = [{"loc": ["path", "actuator_id"], "msg": str(exc), "type": "conflict"}]
    return JSONResponse({"detail": detail}, status_code=status.HTTP_409_CONFLICT)


async def overloaded(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, OverloadedError)
    return JSONResponse(
        {"detail": f"busy: {exc}; retry after {exc.retry_after_s} s"},
        status_code=status.HTTP_503_SERVICE_UNAVAILABLE,
        headers={"Retry-After": str(exc.retry_after_s)},
    )


async def storage(request: Request, exc: Exception) -> JSONResponse:
    """The history cannot take a write (deleted, replaced, read-only, a full disk, a database down): no work is
    started, and nothing is answered 200 that would be lost. No Retry-After: an operator must act."""
    assert isinstance(exc, StorageError)
    return JSONResponse(
        {"detail": f"the history cannot store answers now: {exc}"}, status_code=status.HTTP_503_SERVICE_UNAVAILABLE
    )


async def cancelled(request: Request, exc: Exception) -> JSONResponse:
    """The client is gone; nobody reads this, but the log shows why the request ended."""
    return JSONResponse({"detail": str(exc) or "the client left before its body arrived"}, status_code=499)


async def request_validation_error(request: Request, exc: Exception) -> JSONResponse:
    """Pydantic's errors without the offending input echoed back: it may be huge, or a NaN that
    JSON cannot even carry (the default handler then fails with 500)."""
    assert isinstance(exc, RequestValidationError)
    detail = [{"loc": list(e["loc"]), "msg": e["msg"], "type": e["type"]} for e in exc.errors()]
    return JSONResponse({"detail": detail}, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)


def install(app: FastAPI) -> None:
    app.add_exception_handler(RequestValidationError, request_validation_error)
    app.add_exception_handler(InputError, input_error)
    app.add_exception_handler(OverloadedError, overloaded)
    app.add_exception_handler(ConflictError, conflict)
    app.add_exception_handler(WithdrawnError, withdrawn)
    app.add_exception_handler(VersionContentionError, contended)
    app.add_exception_handler(NotStoredError, not_stored)
    app.add_exception_handler(StorageError, storage)
    app.add_exception_handler(CancelledError, cancelled)
    app.add_exception_handler(ClientDisconnect, cancelled)  # an abandoned upload: a log line, not a traceback
