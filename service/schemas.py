"""Request and response models: the ``ema-window/1``, ``ema-estimate/1`` contracts of interfaces.md."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, FiniteFloat


class FlightConditionIn(BaseModel):
    model_config = ConfigDict(extra="forbid")
    airspeed_mps: FiniteFloat
    altitude_m: FiniteFloat


class SignalsIn(BaseModel):
    model_config = ConfigDict(extra="forbid")
    command_deg: list[FiniteFloat]
    position_deg: list[FiniteFloat]
    motor_speed_radps: list[FiniteFloat]
    current_a: list[FiniteFloat]
    hinge_moment_nm: list[FiniteFloat]


class WindowIn(BaseModel):
    """One logged window. Types and finiteness are checked here; lengths, envelope and ranges by
    ``sim.window.Window``, whose errors come back as 422 naming the same field."""

    model_config = ConfigDict(extra="forbid")
    schema_: Literal["ema-window/1"] = Field(alias="schema")
    actuator_id: str = Field(min_length=1, max_length=200)
    window_id: str = Field(min_length=1, max_length=200)
    sample_rate_hz: FiniteFloat
    flight_condition: FlightConditionIn
    signals: SignalsIn


class TruthIn(BaseModel):
    """The true parameters of synthetic windows, to report the estimation error."""

    model_config = ConfigDict(extra="forbid")
    FDJ: FiniteFloat = Field(gt=0)
    eta_O: FiniteFloat = Field(gt=0, le=1)
    FSJ: FiniteFloat | None = Field(None, gt=0)


class CalibrateIn(BaseModel):
    model_config = ConfigDict(extra="forbid")
    windows: list[WindowIn] = Field(min_length=1, max_length=8)
    truth: TruthIn | None = None


class ParameterEstimate(BaseModel):
    value: float
    std: float | None
    nominal: float
    drift_pct: float


class Estimates(BaseModel):
    FDJ: ParameterEstimate
    eta_O: ParameterEstimate
    eta_A: ParameterEstimate
    FSJ: ParameterEstimate | None
    FSD: dict[str, float] | None = None


class EstimateOut(BaseModel):
    """``ema-estimate/1``; ``id`` and ``stored_at`` locate it in the history."""

    model_config = ConfigDict(populate_by_name=True)
    schema_: Literal["ema-estimate/1"] = Field("ema-estimate/1", alias="schema", serialization_alias="schema")
    id: int
    stored_at: str
    actuator_id: str
    window_id: str
    estimates: Estimates
    fsj_note: str
    timings_s: dict[str, float]
    dataset: dict[str, Any]
    training: dict[str, Any]
    methods: dict[str, Any]


class Trend(BaseModel):
    n: int
    first: float
    last: float
    slope_per_day: float | None  # least-squares slope over the stored time; None with fewer than 2 points
    drift_pct_last: float


class HistoryOut(BaseModel):
    actuator_id: str
    estimates: list[EstimateOut]  # oldest first
    trend: dict[str, Trend]


class HealthOut(BaseModel):
    status: Literal["ok"]
    warm: bool
    running: int
    queued: int
    max_queue: int
