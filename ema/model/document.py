"""The base of every public document ema writes (``ema-estimate/1``, ``ema-calibration/1``, the prognosis)."""

from __future__ import annotations

from typing import Annotated

from pydantic import AllowInfNan, BaseModel, ConfigDict, Strict

Number = Annotated[float, Strict(), AllowInfNan(False)]  # a finite float, never a string or a bool read as one


class Document(BaseModel):
    """A public document: immutable, strict about unknown fields."""

    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)
