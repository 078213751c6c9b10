"""The pipeline's one configuration object, built from ``ema.estimate.sizes`` (the defaults and bounds).

The service's settings, the CLI's flags and their help, and every result (which carries the
config it ran with) read this model; nothing restates a default or a bound.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, ConfigDict, Field, computed_field, model_validator

from ema.estimate.sizes import SIZES
from ema.model.document import renamed


def _field(name: str) -> Any:
    size = SIZES[name]
    return Field(size.default, ge=size.low, le=size.high, description=size.description)


class EarlierCheckWindows(BaseModel):
    """A model holding ``check_simulations``, the held-out simulations that score the estimators, under their
    earlier name too: ``check_windows`` read on input and written beside the new name (ema-estimate/1 as first
    published)."""

    if TYPE_CHECKING:
        check_simulations: int  # each model declares it, with its own bounds

    @model_validator(mode="before")
    @classmethod
    def _earlier_names(cls, values: Any) -> Any:
        return renamed(values, {"check_simulations": "check_windows"})

    @computed_field(description="deprecated alias of check_simulations (ema-estimate/1 as first published)")
    def check_windows(self) -> int:
        return self.check_simulations


class PipelineConfig(EarlierCheckWindows):
    """One window -> estimates: how much to simulate and train (``ema.estimate.sizes`` holds the numbers)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    n_simulations: int = _field("n_simulations")
    check_simulations: int = _field("check_simulations")
    n_timesteps: int = _field("n_timesteps")
    hidden_units: int = _field("hidden_units")
    members: int = _field("members")
    seed: int = _field("seed")

    @property
    def total_simulations(self) -> int:
        return self.n_simulations + self.check_simulations


def bounds(name: str) -> tuple[int, int]:
    """(low, high) of a pipeline size, for the service's query parameters."""
    return SIZES[name].low, SIZES[name].high
