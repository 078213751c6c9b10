"""The base of every public document ema writes (``ema-estimate/1``, ``ema-calibration/1``, the prognosis)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Annotated, Any, TypeVar

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


def renamed(values: Any, names: Mapping[str, str]) -> Any:
    """A document's input with each field's earlier name (``names``: new -> earlier) read as the new one, so that a
    client of the document as first published keeps working; both names given with two values is refused, naming
    the earlier one. For a ``model_validator(mode="before")``."""
    if not isinstance(values, dict):
        return values
    values = dict(values)
    for new, earlier in names.items():
        if earlier in values:
            given = values.pop(earlier)
            if values.setdefault(new, given) != given:
                raise ValueError(f"{earlier}: is the earlier name of {new}; give one of them")
    return values


class Document(BaseModel):
    """A public document: immutable, strict about unknown fields."""

    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)
