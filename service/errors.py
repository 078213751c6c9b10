"""Errors as HTTP answers: bad input 422 naming the field, overload 503 with Retry-After."""

from __future__ import annotations

from fastapi import FastAPI, Request, status
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse

from service.jobs import CancelledError, OverloadedError
from sim.checks import InputError


def _location(field: str) -> list[str]:
    """``signals.current_a`` -> ["body", "signals", "current_a"]; query parameters keep "query"."""
    if field.startswith("query."):
        return ["query", *field.split(".")[1:]]
    if field == "body":
        return ["body"]
    return ["body", *field.split(".")]


async def input_error(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, InputError)
    detail = [{"loc": _location(exc.field), "msg": exc.message, "type": "value_error"}]
    return JSONResponse({"detail": detail}, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)


async def overloaded(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, OverloadedError)
    return JSONResponse(
        {"detail": f"busy: {exc}; retry after {exc.retry_after_s} s"},
        status_code=status.HTTP_503_SERVICE_UNAVAILABLE,
        headers={"Retry-After": str(exc.retry_after_s)},
    )


async def cancelled(request: Request, exc: Exception) -> JSONResponse:
    """The client is gone; nobody reads this, but the log shows why the request ended."""
    return JSONResponse({"detail": str(exc)}, status_code=499)


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
    app.add_exception_handler(CancelledError, cancelled)
