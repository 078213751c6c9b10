"""The service's own request and response models; the documents themselves are defined once, below:
``ema.model.window.WindowDocument``, ``ema.estimate.documents.Estimate``,
``ema.calibration.documents.CalibrationReport``,
``ema.prognosis.documents.EstimateHistory`` and ``Prognosis``."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, FiniteFloat

from ema.model.window import WindowDocument


class ErrorItem(BaseModel):
    loc: list[str | int] = Field(description="where: body, query or header, then the field")
    msg: str
    type: str


class ErrorOut(BaseModel):
    detail: list[ErrorItem]


class BusyOut(BaseModel):
    detail: str


Truth = Annotated[
    dict[str, FiniteFloat],
    Field(
        min_length=1,
        description="the true values of synthetic windows by name (FDJ and eta_O of a rotary EMA, a servo's mass): "
        "the report states its error against each constant it reports; each held to its document field's bounds",
        examples=[{"FDJ": 0.05, "eta_O": 0.85}],
    ),
]


class CalibrateIn(BaseModel):
    model_config = ConfigDict(extra="forbid")
    windows: list[WindowDocument] = Field(min_length=1, max_length=16, description="windows of one actuator")
    truth: Truth | None = None


class HealthOut(BaseModel):
    status: Literal["ok", "degraded"]
    warm: bool
    running: int
    queued: int
    max_queue: int
    storage: str = Field(description="'ok', or what is wrong with the history file")


def responses(*codes: int) -> dict[int | str, dict[str, Any]]:
    """The error answers a route may give, for its OpenAPI entry."""
    described = {
        401: {"model": ErrorOut, "description": "missing or wrong X-API-Key"},
        403: {"model": ErrorOut, "description": "a write from a page of another origin (a browser's Origin header)"},
        404: {"model": ErrorOut, "description": "nothing stored under the path's actuator_id"},
        409: {"model": ErrorOut, "description": "another window's content under a stored (actuator_id, window_id)"},
        410: {"model": ErrorOut, "description": "a window an operator withdrew, posted again: it stays withdrawn"},
        413: {"model": ErrorOut, "description": "the body exceeds EMA_MAX_BODY_BYTES"},
        415: {"model": ErrorOut, "description": "the body is not application/json"},
        422: {"model": ErrorOut, "description": "bad input or over the request budget; `loc` names the field"},
        503: {
            "model": BusyOut,
            "description": "the queue is full or the job could not start in time",
            "headers": {"Retry-After": {"schema": {"type": "integer"}, "description": "seconds"}},
        },
    }
    return {code: described[code] for code in codes}


def json_body(model: type[BaseModel], description: str) -> dict[str, Any]:
    """An OpenAPI requestBody for a body the route reads itself (to parse it off the event loop)."""
    return {
        "requestBody": {
            "required": True,
            "description": description,
            "content": {"application/json": {"schema": {"$ref": f"#/components/schemas/{model.__name__}"}}},
        }
    }
