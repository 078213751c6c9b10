"""The history and prognosis documents (``docs/prognosis.md``): one definition each.

``GET /v1/actuators/{id}/estimates`` answers :class:`EstimateHistory`, ``.../prognosis`` answers
:class:`Prognosis`, ``ema history`` prints and plots them, and docs/schemas/ holds their JSON
Schemas.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, TypeAdapter

from ema.estimate.documents import Estimate, Notes
from ema.estimate.documents.window_facts import InertiaReading
from ema.model.actuator import AnyActuator
from ema.model.document import Document

PARAMETERS = ("FDJ", "eta_O", "eta_A")
TimeUnit = Literal["flight_hours", "days", "windows"]
# The least spread a trend needs before it forecasts anything (and a status may say "due"): windows logged
# within minutes of each other show noise, not wear, however steep their line.
MIN_SPAN: dict[str, float] = {"flight_hours": 10.0, "days": 2.0, "windows": 5.0}


class Stored(Estimate):
    """An ``ema-estimate/1`` result as the history keeps it."""

    id: int
    stored_at: str = Field(description="when the service stored it (UTC, ISO 8601)")
    replay: bool = Field(False, description="this window was posted before: the stored answer, not recomputed")


class StoredActuator(Document):
    """An actuator's ``ema-actuator/1`` document as the service keeps it: one version of several."""

    actuator_id: str
    version: int = Field(ge=1, description="1 for the first document PUT, then one more for each that differs")
    stored_at: str = Field(description="when this version was stored (UTC, ISO 8601)")
    document: AnyActuator


class Withdrawal(Document):
    """A window taken out of an actuator's history (``DELETE .../estimates/{window_id}``): kept, with why."""

    actuator_id: str
    window_id: str
    withdrawn_at: str = Field(description="when it was withdrawn (UTC, ISO 8601)")
    reason: str = Field(description="what the operator said, or that none was given")
    stored_at: str = Field(description="when it had been stored")
    content_sha256: str | None = Field(description="the window's digest as stored (null: stored before digests)")


class Point(Document):
    """One window's estimate of one parameter, at its time."""

    window_id: str
    time: float = Field(description="in the prognosis's time unit")
    value: float
    std: float | None
    outlier: bool = False


class Curved(Document):
    """The quadratic beside the line, value(t) = level + slope·dt + curvature·dt² (dt = t − t_last), and the
    weight the windows give it against the line: wear that speeds up."""

    level: float
    slope_per_unit: float
    curvature_per_unit2: float
    covariance: list[list[float]] = Field(description="of (level, slope, curvature), 3 x 3")
    weight: float = Field(ge=0, le=1, description="posterior weight of the curve against the line (BIC)")

    def value_at(self, offset: float | np.ndarray) -> float | np.ndarray:
        return self.level + self.slope_per_unit * offset + self.curvature_per_unit2 * offset**2


class ForecastPoint(Document):
    """The forecast at one time: the median of the weighed laws' curves and their 90 % band."""

    time: float
    median: float
    low: float = Field(description="5 % quantile")
    high: float = Field(description="95 % quantile")


class Trend(Document):
    """value(t) = level + slope·(t − t_last), weighted by each window's std, robust to outliers; beside it
    the curve where the windows bend (``curved``)."""

    parameter: str
    n: int
    level: float = Field(description="the line's value at the last window (with the curve weighed in: now())")
    level_std: float
    slope_per_unit: float = Field(description="0 where the windows span no time (slope_std null)")
    slope_std: float | None = Field(
        description="null: the windows span no time (one window, or all at one time): a level with no slope"
    )
    level_slope_correlation: float = Field(
        0.0, ge=-1, le=1, description="of the level's and the slope's errors (the level is quoted at the last window)"
    )
    excess_std: float = Field(description="scatter beyond the stated stds, added to every point's (0: none)")
    points: list[Point]
    curved: Curved | None = Field(None, description="the quadratic and its weight (null: too few windows to bend)")
    laws: dict[str, float] = Field(
        default_factory=dict,
        description="each degradation law's weight: how well it predicted the later windows from the earlier ones "
        "(linear, quadratic, exponential, power, knee); the forecast draws from each in that share",
    )
    forecast: list[ForecastPoint] = Field(
        default_factory=list, description="the weighed laws' median and 90 % band, from the first window on"
    )

    def now(self) -> tuple[float, float]:
        """The value at the last window and its std, the line's and the curve's weighed by the curve's weight."""
        if self.curved is None:
            return self.level, self.level_std
        w, curve_std = self.curved.weight, float(np.sqrt(max(self.curved.covariance[0][0], 0.0)))
        value = (1 - w) * self.level + w * self.curved.level
        spread = (1 - w) * self.level_std**2 + w * curve_std**2 + w * (1 - w) * (self.curved.level - self.level) ** 2
        return float(value), float(np.sqrt(spread))

    def std_at(self, offset: float) -> float:
        """The std of the trend's value ``offset`` time units after the last window (level and slope correlated)."""
        if self.slope_std is None:
            return self.level_std if offset == 0 else float("inf")
        level, slope = self.level_std, self.slope_std * offset
        return float(np.sqrt(max(level**2 + 2 * self.level_slope_correlation * level * slope + slope**2, 0.0)))


class RemainingLife(Document):
    parameter: str
    threshold: float
    direction: Literal["above", "below"]
    status: Literal[
        "crossing predicted", "already crossed", "no degradation detected", "too few windows", "span too short"
    ] = Field(
        description="too few windows: under 3 read the parameter; span too short: they cover less time than a "
        "trend needs (MIN_SPAN: 10 flight hours, 2 days or 5 windows), so no forecast is made"
    )
    rul: float | None = Field(description="time from the last window to the crossing, in the time unit")
    rul_low: float | None = Field(description="5 % quantile")
    rul_high: float | None = Field(description="95 % quantile (null: beyond any horizon the data support)")
    rul_earliest: float | None = Field(
        None,
        description="the earliest plausible crossing: the 5 % quantile of the law that crosses soonest of those "
        "holding some weight (plan for it if the wear is of that kind)",
    )
    speeding_up: bool = Field(False, description="the latest windows move towards the threshold faster than the trend")
    probability_degrading: float | None = Field(description="probability that the trend moves towards the threshold")


class BacktestPoint(Document):
    """The prognosis as it stood at an earlier window, from the windows up to it alone, against what came after."""

    window_id: str = Field(description="the last window it saw")
    time: float
    windows: int = Field(description="how many windows it saw")
    status: str
    rul: float | None
    rul_low: float | None
    rul_high: float | None
    crossing: float | None = Field(description="the crossing time it predicted (time + rul)")
    later_windows: int
    later_inside: float | None = Field(
        description="share of the later windows inside the forecast's 90 % band then (null: beyond its reach)"
    )


class Prognosis(Document):
    actuator_id: str
    time_unit: TimeUnit = Field(
        description="flight_hours where every window gives them, else days from recorded_at, else windows: "
        "trended in the order they were stored, a remaining life counted in windows"
    )
    trends: dict[str, Trend]
    remaining_life: dict[str, RemainingLife]
    sensors: dict[str, Trend] = Field(
        default_factory=dict,
        description="trends of what the windows read of the sensors: hinge_aircraft_ratio, the strain gauge's gain "
        "against the aircraft model (1 where they agree; a level off 1 in every window is the gauge's calibration or "
        "the airframe's C_hδ, a slope the gauge drifting)",
    )
    constants: dict[str, Trend] = Field(
        default_factory=dict,
        description="trends of the other constants the windows read beside the health (a servo's mass, its viscous "
        "friction, a geared servo's loop gain), each over the windows that read it: no failure level, no remaining "
        "life, a change to see",
    )
    notes: Notes = Field(default_factory=list)
    backtest: dict[str, list[BacktestPoint]] = Field(
        default_factory=dict,
        description="per parameter, the prognosis as it would have stood at earlier windows, against what came after",
    )

    def life_status(self, parameter: str) -> str:
        """``parameter``'s remaining life's status in words, saying where its history moves away from the level
        that life watches (a ``moving_away`` note): no degradation towards that level, a change all the same."""
        life = self.remaining_life[parameter]
        if not any(n.code == "moving_away" and n.parameter == parameter for n in self.notes):
            return life.status
        return f"{life.status} towards the level {life.direction}; moving away from it: a change"


class RotaryPrognosis(Prognosis):
    """A rotary actuator's prognosis: beside its trends, J_M as its windows read it (kept with the build)."""

    inertia: InertiaReading | None = Field(
        None,
        description="the actuator's J_M as its windows that told a heavier rotor from a weaker motor read it: "
        "what a window that cannot is read with (null: none read one)",
    )


KINDS_PROGNOSES: tuple[type[Prognosis], ...] = (RotaryPrognosis,)  # each a kind's own parts beside the shared
AnyPrognosis = Annotated[Prognosis | RotaryPrognosis, Field(union_mode="left_to_right")]  # the shared, else its own
PROGNOSIS: TypeAdapter[Prognosis] = TypeAdapter(AnyPrognosis)  # what parses and exports a prognosis


def own_parts(cls: type[Prognosis]) -> set[str]:
    """The fields a kind's prognosis class adds to the shared ones."""
    return set(cls.model_fields) - set(Prognosis.model_fields)


def prognosis_class(parts: Mapping[str, Any]) -> type[Prognosis]:
    """The class of a prognosis whose kind adds ``parts`` (``ema.kinds.prognosis_parts``): the shared one where it
    adds none, else the one whose own fields they are."""
    if not parts:
        return Prognosis
    return next(cls for cls in KINDS_PROGNOSES if own_parts(cls) == set(parts))


def prognosis_schema() -> dict[str, Any]:
    """The JSON Schema of a prognosis: the shared document, or a kind's with its own parts."""
    return {"title": "Prognosis", **PROGNOSIS.json_schema(by_alias=True)}


class EstimateHistory(Document):
    actuator_id: str
    estimates: list[Stored] = Field(description="oldest first; one per (actuator_id, window_id)")
    legacy: list[dict[str, Any]] = Field(
        default_factory=list, description="results an earlier version stored, in their own format, as stored"
    )
    withdrawn: list[Withdrawal] = Field(
        default_factory=list, description="windows taken out of the history, with when and why (oldest first)"
    )


class Threshold(Document):
    level: float
    direction: Literal["above", "below"]


class ActuatorSummary(Document):
    """One actuator as the fleet view and ``GET /v1/actuators`` list it: its status, its latest estimate and its
    most urgent remaining life (``ema.prognosis.status``)."""

    actuator_id: str
    status: Literal["due", "watch", "healthy", "not enough history", "prognosis failed", "pending"] = Field(
        description="pending: windows arrived since its prognosis was last computed and it is being brought up to "
        "date (the figures are those of the line as it was, where there was one)"
    )
    reason: str = Field(description="why this status, in words")
    windows: int = Field(ge=0, description="estimates stored")
    time_unit: TimeUnit | None = Field(None, description="of soonest and remaining_life (null: no estimates)")
    soonest: float | None = Field(None, description="the earliest plausible crossing of any parameter, from now")
    remaining_life: RemainingLife | None = Field(None, description="the most urgent parameter's")
    latest_window_id: str | None = None
    latest_when: str | None = Field(None, description="its flight hours or recorded_at as logged (null: neither)")
    estimates: dict[str, float | None] = Field(
        default_factory=dict, description="the latest window's FDJ, eta_O and eta_A (null: not read)"
    )
    stds: dict[str, float | None] = Field(default_factory=dict)
    units: dict[str, str] = Field(
        default_factory=dict,
        description="each latest estimate's unit (N·m at the motor shaft, N on the load, 1 for an efficiency)",
    )
    nominal: dict[str, float] = Field(default_factory=dict)
    thresholds: dict[str, Threshold] = Field(default_factory=dict)
    thresholds_below: dict[str, Threshold] = Field(
        default_factory=dict, description="a parameter's lower level where the document gives one beside its upper"
    )
    repeatability_stds: dict[str, float | None] = Field(
        default_factory=dict, description="the latest estimate's repeatability stds, what changes are judged on"
    )
    reproduced: bool | None = Field(None, description="the model reproduced the latest window")
    document: str = Field(description="the name of the ema-actuator/1 document it is read with")
    document_version: int | None = Field(None, description="its stored version (null: the default document)")
