"""The base of every public document ema writes (``ema-estimate/1``, ``ema-calibration/1``, the prognosis)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, TypeVar

from pydantic import AfterValidator, AllowInfNan, BaseModel, ConfigDict, Strict

Number = Annotated[float, Strict(), AllowInfNan(False)]  # a finite float, never a string or a bool read as one
T = TypeVar("T")


def refused_by(rule: Callable[[T], str | None]) -> AfterValidator:
    """A field's validator from ``rule``, which says why a value is refused (None: it is not): one rule then
    serves a document's field, a setting and a route alike, with the same message."""

    def check(value: T) -> T:
        reason = rule(value)
        if reason is not None:
            raise ValueError(reason)
        return value

    return AfterValidator(check)


class Document(BaseModel):
    """A public document: immutable, strict about unknown fields."""

    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)
