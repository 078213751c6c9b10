"""Input validation shared by every layer: one error type that names the offending field."""

from __future__ import annotations

import math
from collections.abc import Callable, Container
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import pydantic_core
from pydantic import BaseModel, Discriminator, TypeAdapter, ValidationError


class InputError(ValueError):
    """Bad input; ``field`` names the argument or window field at fault."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message


Parsed = TypeVar("Parsed")
Model = TypeVar("Model", bound=BaseModel)


def load_json(path: str | Path) -> Any:
    """The JSON value in the file at ``path``; one that cannot be read or parsed is an InputError naming it.
    Parsed by pydantic's own parser: the same values as the standard library's, four times faster on a window's
    thousands of numbers (a fleet's archive is read while its workers wait)."""
    try:
        text = Path(path).read_bytes()
    except OSError as exc:
        raise InputError(str(path), f"cannot be read ({exc.strerror})") from None
    if not text.strip():
        raise InputError(str(path), "is empty" if not text else "holds only white space, no JSON")
    try:
        return pydantic_core.from_json(text)
    except ValueError as exc:
        raise InputError(str(path), f"cannot be read as JSON ({exc})") from None


def read_document(path: str | Path, parse: Callable[[Any], Parsed]) -> Parsed:
    """``parse`` of the JSON in the file at ``path``; its errors name the file before the field."""
    document = load_json(path)
    try:
        return parse(document)
    except InputError as exc:
        raise InputError(f"{path}: {exc.field}", exc.message) from None


def validated(
    model: type[Model] | TypeAdapter[Model], document: Any, what: str, prefix: str = "", tags: tuple[str, ...] = ()
) -> Model:
    """``document`` (a dict) validated as ``model`` (a class, or a union of documents through its adapter);
    anything else, or a field it refuses, is an InputError naming it (``what``: the document's name where the whole
    is wrong; ``prefix`` before a field's name: where it came from, ``query.``; ``tags``: ``from_validation``'s)."""
    if not isinstance(document, dict):
        raise InputError(what, f"must be a JSON object, got {type(document).__name__}")
    try:
        return model.validate_python(document) if isinstance(model, TypeAdapter) else model.model_validate(document)
    except ValidationError as exc:
        raise from_validation(exc, prefix, tags) from None


def finite_array(field: str, values: object, ndim: int | None = None) -> np.ndarray:
    """Return ``values`` as a float64 array, refusing NaN/inf and the wrong number of dimensions."""
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(field, f"must be numeric ({exc})") from None
    if ndim is not None and array.ndim != ndim:
        raise InputError(field, f"must have {ndim} dimension(s), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        bad = int(np.flatnonzero(~np.isfinite(array.ravel()))[0])
        raise InputError(field, f"contains NaN or inf (first at flat index {bad})")
    return array


def in_range(field: str, value: float | str, low: float, high: float, unit: str = "") -> float:
    """Return ``value`` (a number, or text that reads as one) as a float if it lies in [low, high], else raise
    naming the field."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"must be a number, got {value!r}") from None
    if not math.isfinite(number) or not low <= number <= high:
        raise InputError(field, f"{number:g} is outside [{low:g}, {high:g}] {unit}".rstrip())
    return number


def array_in_range(field: str, values: np.ndarray, low: float, high: float, unit: str = "") -> None:
    """Raise naming the field if any element lies outside [low, high]."""
    outside = (values < low) | (values > high)
    if np.any(outside):
        first = float(values.ravel()[np.flatnonzero(outside.ravel())[0]])
        raise InputError(field, f"value {first:g} is outside [{low:g}, {high:g}] {unit}".rstrip())


BOUND_ERRORS = ("greater_than", "greater_than_equal", "less_than", "less_than_equal")  # pydantic's, on a number
UNKNOWN_TAG = "unknown_tag"  # a tagged union's error where the tag names no member ("kind: is one of ...")


Unnamed = str | Callable[[dict], str]  # the kind of a document that names none: one, or read from its content


def _unnamed(document: dict, default: Unnamed) -> str:
    return default if isinstance(default, str) else default(document)


def kind_named(values: Any, default: Unnamed, kinds: Container[str], *, shared: type | None = None) -> str | None:
    """The kind a document's input names (``default`` where it names none), or None where the input is no object
    or names no kind of ``kinds`` (the union's discriminator refuses it, naming the field). ``shared``: the class
    every kind's extends, validated itself: a TypeError, as it holds no document alone."""
    if shared is not None:
        raise TypeError(f"{shared.__name__} holds what every kind shares, no document alone: parse through the union")
    if not isinstance(values, dict):
        return None
    kind = values["kind"] if "kind" in values else _unnamed(values, default)
    return kind if isinstance(kind, str) and kind in kinds else None


def tagged_by(field: str, names: tuple[str, ...], default: Unnamed) -> Discriminator:
    """The discriminator of a union of documents told apart by ``field`` (one of ``names``; ``default`` where a
    document gives none, as documents first written without it): an unknown value refused naming the field."""

    def tag(document: Any) -> Any:
        if isinstance(document, dict):
            return document[field] if field in document else _unnamed(document, default)
        return getattr(document, field, None)

    return Discriminator(
        tag, custom_error_type=UNKNOWN_TAG, custom_error_message=f"{field}: is one of {', '.join(names)}"
    )


def from_validation(exc: Any, prefix: str = "", tags: tuple[str, ...] = ()) -> InputError:
    """A pydantic ValidationError's first error as an InputError naming the field (list indices go
    into the message: ``signals.current_a``, "sample 17: Input should be a finite number"). A check across
    fields names the one it reports on first in its message ("fsj_nm: ..."): that field is named. ``tags``: a
    tagged union's member names, which pydantic puts in the field's path and the document does not hold."""
    first = exc.errors()[0]
    loc = [part for part in first["loc"] if part not in tags]
    names = [str(part) for part in loc if not isinstance(part, int)]
    indices = [part for part in loc if isinstance(part, int)]
    said = first["msg"].removeprefix("Value error, ")
    given = first.get("input")
    if first["type"] in BOUND_ERRORS and isinstance(given, int | float | str):
        said += f", got {given:g}" if isinstance(given, int | float) else f", got {given!r}"
    message = said if not indices else f"sample {indices[0]}: {said}"
    head, _, rest = message.partition(": ")
    if first["type"] in ("value_error", UNKNOWN_TAG) and rest and head.replace("_", "").replace(".", "").isalnum():
        names, message = [*names, head], rest
    return InputError(prefix + (".".join(names) or "document"), message)
