"""The pipeline's one configuration: sizes, their defaults and their bounds, defined here only.

The service's settings, the CLI's flags and their help, and every result (which carries the
config it ran with) read this model; nothing restates a default or a bound.
"""

from __future__ import annotations

from typing import Any, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from sim.checks import from_validation

Model = TypeVar("Model", bound=BaseModel)


class PipelineConfig(BaseModel):
    """One window -> estimates: how much to simulate and train."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    n_simulations: int = Field(96, ge=16, le=4000, description="simulations the network trains on")
    check_windows: int = Field(32, ge=8, le=1000, description="held-out simulations that score the estimators")
    n_timesteps: int = Field(500, ge=10, le=10_000, description="network input timesteps (bins of the window)")
    hidden_units: int = Field(100, ge=1, le=2000, description="hidden neurons")
    members: int = Field(1, ge=1, le=20, description="networks in the ensemble")
    seed: int = Field(0, ge=0, le=2**32 - 1, description="seed of the dataset and the training")

    @property
    def total_simulations(self) -> int:
        return self.n_simulations + self.check_windows


def validated(model: type[Model], values: dict[str, Any], prefix: str = "") -> Model:
    """``model(**values)``, its first error as an InputError naming the field (``prefix`` + name)."""
    try:
        return model(**values)
    except ValidationError as exc:
        raise from_validation(exc, prefix) from None


def bounds(model: type[BaseModel], name: str) -> tuple[float | None, float | None]:
    """(ge, le) of a field, for help texts and the service's per-request limits."""
    low = high = None
    for item in model.model_fields[name].metadata:
        low = getattr(item, "ge", low)
        high = getattr(item, "le", high)
    return low, high
