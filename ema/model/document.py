"""The base of every public document ema writes (``ema-estimate/1``, ``ema-calibration/1``, the prognosis)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class Document(BaseModel):
    """A public document: immutable, strict about unknown fields."""

    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)
