"""``ema-calibration/1``: the one definition of a calibration report (``docs/calibration.md``).

What every kind's report holds is ``CalibrationReport``; each kind's class adds what only its loop answers
(``LinearCalibration`` its drive and faulted runs' changes, ``ServoCalibration`` its constants as simulated), and
``AnyCalibration`` joins them on ``kind``. The loop returns one, ``POST /v1/calibrate`` declares the union,
``ema calibrate`` prints it, the history stores it, the study in benchmarks/ reads it;
docs/schemas/ema-calibration-1.json is exported from it.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, Tag, TypeAdapter, model_validator

from ema.model.actuator import AnyActuator
from ema.model.checks import kind_named, tagged_by
from ema.model.document import Document
from ema.model.kinds import DEFAULT_KIND, KIND_NAMES


class Candidate(Document):
    effect: str = Field(description="a named effect, or 'friction vs <variable>' for a generic curve")
    follows: str = Field(description="the variable its trace follows")
    named: bool
    parameters: dict[str, float] = Field(description="at its best; a curve as value per grid point")
    rms_reduction: float = Field(description="1 − √(residual with it / without), in sample")
    held_out_drop: float = Field(description="fractional drop of the held-out residual")
    score: float = Field(description="z: held-out drop in noise-floor stds above what noise alone gives")
    plausible: bool = Field(description="the simulator can add it with these parameters")


class Step(Document):
    selected: str | None
    reason: str
    indistinguishable_from: list[str] = Field(default_factory=list)
    tie_break_output_error: dict[str, float] | None = None


class Unexplained(Document):
    """Structure no named effect matches, described rather than named."""

    adopted: bool = Field(
        False,
        description="the term is in the estimates after (it predicts held-out folds "
        "better and its estimates are identified), as a named effect would be",
    )
    variables: list[str] = Field(description="what the residual follows (several: the windows cannot tell which)")
    description: str
    shape: dict[str, float] = Field(description="extra friction [N·m] at grid points of the first variable")
    simulator_term: dict | None = Field(description="a FrictionTable the simulator can add; null where it has none")
    estimates_if_added: dict[str, float] | None = Field(
        description="FDJ and η_O re-estimated with the term; null where not identified (see estimates_withheld)"
    )
    estimates_withheld: str | None = Field(default=None, description="why estimates_if_added is null")
    residual_rms_if_added: float
    error_if_added: dict[str, float] | None = None


class Ambiguity(Document):
    """Two or more effects read the windows about as well and move the estimates apart: none is adopted."""

    effects: list[str] = Field(description="the effect selection would have adopted, then its rivals")
    readings: dict[str, dict[str, float]] = Field(description="FDJ and η_O re-estimated with each")
    stds_after: dict[str, float] = Field(
        description="the base estimates' stds, widened until ±2 std holds each reading"
    )
    tell_apart: str = Field(description="what data would tell the effects apart")
    reason: str


class DriveLearned(Document):
    """What healthy runs of a linear actuator taught of its drive (``ema calibrate`` on a document lacking it)."""

    runs: int
    loads_n: list[float] = Field(description="the load sizes the runs held [N]")
    current_per_nm_a: float = Field(description="c: drive current per N·m of motor torque along the motion")
    current_per_nm_std_a: float
    current_at_zero_torque_a: float = Field(description="I0: the runs' mean current at rest (FDJ's anchor)")
    current_at_zero_torque_std_a: float = Field(description="its spread over the runs")
    fdj_nm: float | None = Field(description="the nominal FDJ (null: runs at one load size cannot read it)")
    fdj_std_nm: float | None
    eta_o: float | None = Field(description="the nominal η_O (null: runs at one load size cannot read it)")
    eta_o_std: float | None
    repeatability_nm: float = Field(description="the run-to-run std of FDJ beyond each run's own noise")
    run_to_run_nm: float | None = Field(
        None, description="the sd of one run's FDJ within a set of one load (null: one load size)"
    )
    healthy_set_nm: float | None = Field(
        None, description="how far a healthy set's mean sits off the nominal (null: one load size)"
    )
    not_separable: list[str] = Field(description="constants these runs cannot tell apart, and how they were read")


class Learned(Document):
    """A constant the windows taught, in the actuator document's words: one consistent model. A constant that
    differs with the direction of motion is named twice, ``_up`` (towards increasing position) and ``_down``."""

    name: str = Field(description="FDJ, mass, viscous, offset, current_per_nm, …; with _up and _down where it differs")
    value: float
    std: float = Field(description="one standard deviation, in its unit")
    unit: str


class Change(Document):
    """A parameter of faulted runs against the calibrated document's nominal."""

    parameter: str
    load_n: float | None = Field(None, description="the load the runs were logged at [N], where read per load")
    nominal: float
    value: float
    std: float = Field(description="of the runs' combined value (their repeatability included)")
    z: float = Field(description="(value − nominal) / std")
    departed: bool = Field(
        False,
        description="the change, either way, lies beyond what runs of one state show (a fall of friction as well as "
        "a rise)",
    )
    unit: str | None = None
    said: str


class NoiseFloor(Document):
    copies: int
    equation_error_ratio: float = Field(description="RMS of the measured Eq. 5.1 residual over the copies' mean")


class HeldOut(Document):
    """The model re-estimated on four folds, predicting the fifth, in turn: with the effects and without."""

    rss_before: float = Field(description="held-out residual sum of squares of the base model [N²·m²]")
    rss_after: float = Field(description="the same with the effects in")
    adopted: bool
    note: str


class CalibrationReport(Document):
    """``ema-calibration/1``: what every kind's report holds. A report is one kind's class (``RotaryCalibration``,
    ``LinearCalibration``, ``ServoCalibration``), which adds what only that kind's loop answers."""

    schema_: Literal["ema-calibration/1"] = Field("ema-calibration/1", alias="schema")
    kind: str  # each kind's class narrows it to its name
    n_windows: int
    noise_floor: NoiseFloor | None = Field(
        description="the base model's residual against what noise-only copies of the windows leave (null: the kind "
        "draws no copies, as a ball screw's drive calibration, which reads its runs' spread instead)"
    )
    residual_rms_before: dict[str, float]
    residual_rms_after: dict[str, float]
    candidates: list[Candidate]
    selected_effect: str | None = Field(description="the first effect named; null when noise explains the residual")
    selected_effects: list[str]
    selected_parameters: dict[str, float] | None
    effects: dict = Field(description="what the simulator adds: named effects' parameters and a friction table")
    selection_steps: list[Step]
    held_out: HeldOut
    estimates_before: dict[str, float]
    estimates_after: dict[str, float]
    stds_before: dict[str, float] | None = Field(
        None, description="of the base estimates, over the windows (inverse-variance)"
    )
    stds_after: dict[str, float] | None = Field(
        None, description="of the estimates after: the base ones, widened where an ambiguity keeps two readings open"
    )
    learned: list[Learned] = Field(
        default_factory=list,
        description="what the windows taught that the document lacks, each with its std and unit (a servo's mass, "
        "viscous friction, FDJ and offset, an adopted effect's constants; a stepper's drive)",
    )
    model_error_pct_before: dict[str, float] | None = Field(
        None,
        description="per signal: 100·‖y − ŷ‖/‖y‖, the model's reconstruction of the log (the identification "
        "benchmarks' error) with the base model",
    )
    model_error_pct_after: dict[str, float] | None = Field(None, description="the same with the effects in")
    error_before: dict[str, float] | None = Field(
        None,
        description="against a known truth (synthetic windows): |value − truth| of each constant the truth names that "
        "the report carries, with the document's model (null: no truth given, or the constant has no value before)",
    )
    error_after: dict[str, float] | None = Field(None, description="the same with what the windows taught")
    error_pct_before: dict[str, float] | None = Field(None, description="error_before over |truth|, in %")
    error_pct_after: dict[str, float] | None = Field(None, description="error_after over |truth|, in %")
    completed_actuator: AnyActuator | None = Field(
        None,
        description="the actuator's ema-actuator/1 document completed with what the windows taught (a linear "
        "actuator's drive, a servo's load): store it with PUT /v1/actuators/{id} (null: nothing to complete)",
    )
    timings_s: dict[str, float]

    @model_validator(mode="before")
    @classmethod
    def _its_own_parts(cls, values: Any) -> Any:
        """The report's input without another kind's parts where they are empty (as reports were first written,
        every part in each), refused where they hold anything. The shared class alone holds no report."""
        kind = kind_named(values, kind_written, KIND_NAMES, shared=cls if cls is CalibrationReport else None)
        if kind is None:
            return values
        own = _PARTS.get(kind, ())
        others = [part for parts in _PARTS.values() for part in parts if part not in own]
        for part in others:
            if values.get(part):
                raise ValueError(f"{part}: a {kind} actuator's report has no {part} (kind: {kind})")
        return {k: v for k, v in values.items() if k not in others}


_KIND_DESCRIPTION = "the kind of actuator the windows are of (reports first written without it read by their parts)"


class RotaryCalibration(CalibrationReport):
    """A rotary actuator's report: what no named effect explains, and effects its windows cannot tell apart."""

    kind: Literal["rotary"] = Field("rotary", description=_KIND_DESCRIPTION)
    unexplained: Unexplained | None
    ambiguity: Ambiguity | None = Field(
        None, description="effects the windows cannot choose between whose estimates differ (null: none)"
    )


class LinearCalibration(CalibrationReport):
    """A linear actuator's report: what its healthy runs taught of its drive, or what its faulted runs changed."""

    kind: Literal["linear"] = Field("linear", description=_KIND_DESCRIPTION)
    drive: DriveLearned | None = Field(
        None, description="its drive as its healthy runs taught it (null: not a learning run)"
    )
    changes: list[Change] = Field(default_factory=list, description="its faulted runs against its calibrated nominal")


class ServoCalibration(CalibrationReport):
    """A servo's report: its learned constants also as the simulator takes them."""

    kind: Literal["servo"] = Field("servo", description=_KIND_DESCRIPTION)
    model_error_pct_document: dict[str, float] | None = Field(
        None,
        description="the same for the document's model as it stands, its constants fixed (null where it holds none): "
        "how well what was learned before reads these windows",
    )
    as_simulated: list[Learned] = Field(
        default_factory=list,
        description="its learned constants as the simulator takes them, what the completed document keeps: "
        "each moved by what Eq. 5.1 reads of the logs simulated at it (the solution reads a simulated pre-sliding "
        "smaller than it is); the closed loop's error after is at these",
    )


class LoadReading(Document):
    """One load's runs read with the completed document: how their health readings sit (a geared servo's)."""

    load: str = Field(description="the load, for a person (its mass and arm)")
    runs: int
    median: dict[str, float] = Field(description="the runs' median FDJ (fdj_nm), η_O (eta_o), η_A (eta_a)")
    z: dict[str, float] = Field(
        description="(median − nominal) over the nominal's std: within ±2 the load reads the servo the others read"
    )


class GearedCalibration(CalibrationReport):
    """A geared servo's report: its position error before and after, and its runs read per load."""

    kind: Literal["geared"] = Field("geared", description=_KIND_DESCRIPTION)
    position_error_rad: dict[str, float] = Field(
        default_factory=dict,
        description="mean |logged − simulated position| over the runs [rad]: before (a constant friction) and after "
        "(the named effects), in sample and held out (runs a solution did not see)",
    )
    by_load: list[LoadReading] = Field(
        default_factory=list, description="each load's runs read with the completed document, against its nominal"
    )


_PARTS = {  # each kind's own parts of a report, beside the shared ones
    report.model_fields["kind"].default: tuple(
        name for name in report.model_fields if name not in CalibrationReport.model_fields
    )
    for report in (RotaryCalibration, LinearCalibration, ServoCalibration, GearedCalibration)
}


def kind_written(report: dict) -> str:
    """The kind of a report written before reports named it: the one whose parts it fills, else its completed
    document's, else the default (a rotary report held none of the parts)."""
    for kind, parts in _PARTS.items():
        if any(report.get(part) for part in parts):
            return kind
    completed = report.get("completed_actuator")
    named = completed.get("kind") if isinstance(completed, dict) else None
    return named if isinstance(named, str) else DEFAULT_KIND


AnyCalibration = Annotated[
    Annotated[RotaryCalibration, Tag("rotary")]
    | Annotated[LinearCalibration, Tag("linear")]
    | Annotated[ServoCalibration, Tag("servo")]
    | Annotated[GearedCalibration, Tag("geared")],
    tagged_by("kind", KIND_NAMES, kind_written),
]  # ``ema-calibration/1`` as read: one kind's report, by its ``kind``
CALIBRATION_REPORT: TypeAdapter[CalibrationReport] = TypeAdapter(AnyCalibration)  # what parses and exports it


def calibration_schema() -> dict[str, Any]:
    """The JSON Schema of ``ema-calibration/1``: one kind's report, chosen by ``kind``."""
    return {"title": "CalibrationReport", **CALIBRATION_REPORT.json_schema(by_alias=True)}
