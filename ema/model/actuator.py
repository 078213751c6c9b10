"""``ema-actuator/1``: one actuator with its own constants, as its user writes it down.

What every kind's document holds is :class:`ActuatorDocument`, what every stage reads: the nominal health and the
healthy range around it (``ranges``), the prognosis's failure levels (``thresholds``), and optionally the sensors'
noise and the airframe the hinge moment is checked against. Each kind's class adds its own section (the sections'
models: ``ema.model.drive``, ``ema.model.screw``, ``ema.model.servo``): ``RotaryActuator`` its drive (``params``:
the simulator's :class:`~ema.model.params.DriveConstants`, same field names), ``LinearActuator`` its screw,
``ServoActuator`` its servo. ``AnyActuator`` joins them, tagged by ``kind``: a document is read as its kind's
class, and a rotary document may omit ``kind`` (as first published). ``THESIS`` is the thesis's elevator EMA
(Table 3.1), the default wherever a user names none; ``examples/actuator.json`` holds it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

import numpy as np
from pydantic import Field, Tag, TypeAdapter, model_validator
from pydantic.json_schema import DEFAULT_REF_TEMPLATE

from ema.model.aircraft import HingeGeometry
from ema.model.checks import InputError, kind_named, read_document, tagged_by, validated
from ema.model.document import Document, Number
from ema.model.drive import Drive
from ema.model.geared import Geared
from ema.model.kinds import DEFAULT_KIND, KIND_NAMES, KINDS, KindFacts
from ema.model.noise import SensorNoise
from ema.model.params import MAX_CORRELATION_S, DriveConstants, HealthRanges, eta_a_from_eta_o
from ema.model.screw import Screw
from ema.model.servo import Servo

ACTUATOR_SCHEMA = "ema-actuator/1"
DEFAULT_ETA_O_BELOW, THESIS_ETA_O = 0.70, 0.85  # the prognosis's default η_O threshold, at the thesis's nominal
HEALTHY_SPAN = 0.2  # the healthy range: nominal ±20 % (η_O capped below 1), the thesis's §5.4 ranges
MAX_HEALTHY_ETA_O = 0.98
SECTIONS = tuple(kind.section for kind in KINDS.values())  # each kind's own field
_KIND_DESCRIPTION = (
    "rotary: a gear train to a surface (drive); linear: a ball screw turned by a stepper (screw); servo: a linear "
    "axis under a known position controller, logged on the load side (servo); geared: a DC motor, a gear train and its "
    "own position loop, logged at the output shaft (geared)"
)


class Nominal(Document):
    """The health of this actuator new, FDJ in its kind's unit (``ema.model.kinds``: at the motor shaft, or on the
    load for a kind logged on the load side)."""

    fdj_nm: Number | None = Field(
        None,
        ge=1e-6,
        le=100,
        description="FDJ, dynamic friction at the motor shaft (a geared servo's: its output) [N·m]",
    )
    fdj_n: Number | None = Field(
        None, ge=1e-6, le=1e6, description="FDJ, dynamic friction on the load [N] (a kind logged on the load side)"
    )
    eta_o: Number | None = Field(
        None, gt=0, lt=1, description="η_O, efficiency under opposing load (null: never shown, as without a load)"
    )
    eta_a: Number | None = Field(
        None,
        gt=-1,
        lt=1,
        description="η_A, efficiency under aiding load, where read on its own (null: by Eq. 3.4 from η_O and the "
        "gear ratio)",
    )

    @model_validator(mode="before")
    @classmethod
    def _no_null_static_friction(cls, values: Any) -> Any:
        """The input without a null ``fsj_nm`` where the kind reads none (documents were first written with it)."""
        if (
            isinstance(values, dict)
            and "fsj_nm" in values
            and values["fsj_nm"] is None
            and "fsj_nm" not in cls.model_fields
        ):
            return {k: v for k, v in values.items() if k != "fsj_nm"}
        return values

    @model_validator(mode="after")
    def _one_friction(self) -> Nominal:
        if (self.fdj_nm is None) == (self.fdj_n is None):
            raise ValueError("fdj_nm: give the nominal FDJ once, at the motor shaft (fdj_nm) or on the load (fdj_n)")
        return self

    @property
    def fsj(self) -> float | None:
        """The nominal FSJ where the kind reads a static friction (``RotaryNominal``), else None."""
        return None

    @property
    def fdj(self) -> float:
        """The nominal FDJ in the kind's unit."""
        value = self.fdj_nm if self.fdj_nm is not None else self.fdj_n
        assert value is not None  # _one_friction
        return value

    @property
    def efficiency(self) -> float:
        """The nominal η_O; InputError where the document has none (a servo run without a load)."""
        if self.eta_o is None:
            raise InputError("actuator.nominal.eta_o", "is not known: no run with a load has shown it")
        return self.eta_o


class RotaryNominal(Nominal):
    """A rotary actuator's health new: beside its FDJ and η_O, its static (break-away) friction FSJ."""

    fsj_nm: Number | None = Field(
        None, gt=0, le=100, description="FSJ, static (break-away) friction at the motor shaft (a rotary actuator's)"
    )

    @model_validator(mode="after")
    def _static_above_dynamic(self) -> RotaryNominal:
        if self.fsj_nm is not None and self.fdj_nm is not None and self.fsj_nm < self.fdj_nm:
            raise ValueError(
                f"fsj_nm: {self.fsj_nm:g} is below fdj_nm {self.fdj_nm:g}: static friction is never below dynamic"
            )
        return self

    @property
    def fsj(self) -> float | None:
        return self.fsj_nm


class Thresholds(Document):
    """Where each parameter ends the actuator's useful life (the prognosis's failure levels): FDJ above its upper
    level, or below its lower one (a screw that loses its preload loses friction), η_O below its level."""

    fdj_above_nm: Number | None = Field(None, gt=0, le=100, description="default: 1.5x the nominal FDJ")
    fdj_below_nm: Number | None = Field(None, gt=0, le=100, description="default: none (no lower level)")
    fdj_above_n: Number | None = Field(None, gt=0, le=1e6, description="a load-side kind's, in N: default 1.5x")
    fdj_below_n: Number | None = Field(None, gt=0, le=1e6, description="a load-side kind's, in N: default none")
    eta_o_below: Number | None = Field(
        None, gt=0, lt=1, description="default: 0.70, or 0.70/0.85 of a nominal η_O below 0.85"
    )


class SensorNoiseDocument(Document):
    """Each sensor's noise std per sample, and its correlation time (0: white); what ``ema simulate`` draws."""

    position_deg: Number = Field(ge=0, le=1e3)
    motor_speed_radps: Number = Field(ge=0, le=1e3)
    current_a: Number = Field(ge=0, le=1e3)
    hinge_moment_nm: Number = Field(ge=0, le=1e3)
    position_deg_corr_s: Number = Field(0.0, ge=0, le=MAX_CORRELATION_S)
    motor_speed_radps_corr_s: Number = Field(0.0, ge=0, le=MAX_CORRELATION_S)
    current_a_corr_s: Number = Field(0.0, ge=0, le=MAX_CORRELATION_S)
    hinge_moment_nm_corr_s: Number = Field(0.0, ge=0, le=MAX_CORRELATION_S)


class Airframe(Document):
    """The control surface's hinge-moment model, what the logged moment is checked against in flight."""

    area_m2: Number = Field(gt=0, le=100, description="S_e, the surface's area")
    chord_m: Number = Field(gt=0, le=20, description="c_e, its chord")
    ch0: Number = Field(0.0, ge=-1, le=1, description="C_h0")
    ch_alpha_per_rad: Number = Field(ge=-10, le=10, description="C_hα [1/rad]")
    ch_delta_per_rad: Number = Field(ge=-10, le=10, description="C_hδ [1/rad]")
    downwash_gradient: Number = Field(0.4, ge=0, lt=1, description="dε/dα")
    tail_arm_m: Number = Field(4.6, gt=0, le=100, description="l_t, the tail's arm")
    alpha_t_limit_rad: Number = Field(float(np.radians(15.0)), gt=0, le=1.6, description="|α_t| saturation")
    tolerance: Number = Field(
        0.1,
        gt=0,
        le=0.5,
        description="how far this model's C_hδ may be from the real airframe's, relative (a "
        "design estimate's: 10 %); the strain gauge is judged against the model beyond it only",
    )


LOAD_MODEL_TOLERANCE = Airframe.model_fields["tolerance"].default


class ActuatorDocument(Document):
    """``ema-actuator/1``: what every kind's document holds. A document is one kind's class (``RotaryActuator``,
    ``LinearActuator``, ``ServoActuator``), which adds its own section; ``AnyActuator`` joins them on ``kind``."""

    schema_: Literal["ema-actuator/1"] = Field("ema-actuator/1", alias="schema")
    name: str = Field(min_length=1, max_length=200, description="for a person")
    kind: str  # each kind's class narrows it to its name
    nominal: Nominal | None = Field(
        None, description="the health new; a linear actuator's or a servo's is learned by ema calibrate"
    )
    thresholds: Thresholds = Field(default_factory=Thresholds)

    @model_validator(mode="before")
    @classmethod
    def _its_own_section(cls, values: Any) -> Any:
        """The document's input with its kind's section named where missing, and another kind's refused where given
        (a null one, as documents were first written, dropped). The shared class alone holds no document."""
        kind = kind_named(values, DEFAULT_KIND, KINDS, shared=cls if cls is ActuatorDocument else None)
        if kind is None:
            return values
        own = KINDS[kind].section
        kinds_fields = {name for kind in ActuatorDocument.__subclasses__() for name in kind.model_fields}
        values = {k: v for k, v in values.items() if v is not None or k in cls.model_fields or k not in kinds_fields}
        for other in SECTIONS:
            if other != own and other in values:
                raise ValueError(f"{other}: a {kind} actuator has no {other} (kind: {kind})")
        if values.get(own) is None:
            raise ValueError(f"{own}: a {kind} actuator's document gives its {own}")
        return values

    @model_validator(mode="after")
    def _nominal_in_its_unit(self) -> ActuatorDocument:
        if self.facts.nominal_given and (
            self.nominal is None or self.nominal.fsj is None or self.nominal.eta_o is None
        ):
            raise ValueError(f"nominal.fsj_nm: a {self.kind} actuator's document gives its nominal FDJ, FSJ and η_O")
        unit_field = self.facts.friction_field("fdj")
        if self.nominal is not None and getattr(self.nominal, unit_field) is None:
            raise ValueError(f"nominal.{unit_field}: a {self.kind} actuator's FDJ is in {self.facts.friction_unit}")
        return self

    @model_validator(mode="after")
    def _thresholds_past_nominal(self) -> ActuatorDocument:
        if self.nominal is None:
            return self
        for name, nominal in (("FDJ", self.nominal.fdj), ("eta_O", self.nominal.eta_o)):
            for level, way in self.limits(name) if nominal is not None else []:
                assert nominal is not None
                if level <= nominal if way == "above" else level >= nominal:
                    field = self.facts.friction_field(f"fdj_{way}") if name == "FDJ" else "eta_o_below"
                    raise ValueError(f"thresholds.{field}: {level:g} is not {way} the nominal {name} {nominal:g}")
        return self

    @property
    def facts(self) -> KindFacts:
        """What this document's kind is (``ema.model.kinds``)."""
        return KINDS[self.kind]

    @property
    def nominal_class(self) -> type[Nominal]:
        """The class of this kind's nominal health (``RotaryNominal`` beside a static friction)."""
        return Nominal

    @property
    def section(self) -> Drive | Screw | Servo | Geared:
        """The kind's own section of the document (its drive, its screw, its servo)."""
        raise NotImplementedError  # each kind's class

    @property
    def bounding_classes(self) -> tuple[type, ...]:
        """The classes whose fields bound a value read of this actuator: its nominal health's, then its section's."""
        return self.nominal_class, type(self.section)

    @property
    def params(self) -> DriveConstants:
        """The drive's constants as the simulator takes them (a rotary actuator's)."""
        raise InputError("actuator.kind", f"a {self.kind} actuator has no rotary drive to simulate")

    @property
    def gear_ratio(self) -> float:
        """Motor speed over output speed: a gear train's n, a screw's 2π/lead [rad/m], a servo's 1 (its log is on
        the load)."""
        return self.section.gear_ratio

    @property
    def health(self) -> Nominal:
        """The nominal health; InputError where it is not learned yet."""
        if self.nominal is None:
            raise InputError(
                "actuator.nominal",
                "is not known yet: run ema calibrate on healthy runs (a stepper's at two loads) "
                "and read with the document it writes (--out-actuator)",
            )
        return self.nominal

    @property
    def ranges(self) -> HealthRanges:
        """The healthy range around the nominal health: ``HEALTHY_SPAN`` either way, η_O capped below 1 (the thesis's
        nominal where the document has none)."""
        n, span = self.health, HEALTHY_SPAN
        fsj = n.fsj if n.fsj is not None else n.fdj
        eta_o = n.eta_o if n.eta_o is not None else THESIS_ETA_O
        eta = (eta_o * (1 - span), min(eta_o * (1 + span), max(MAX_HEALTHY_ETA_O, eta_o)))
        return HealthRanges(
            fsj_nm=(fsj * (1 - span), fsj * (1 + span)),
            fdj_nm=(n.fdj * (1 - span), n.fdj * (1 + span)),
            eta_o=eta,
            nominal_fsj_nm=fsj,
            nominal_fdj_nm=n.fdj,
            nominal_eta_o=eta_o,
        )

    @property
    def load_model_tolerance(self) -> float:
        """How far the model a logged load is checked against may be from the real one, relative: a trend of the
        load sensor's gain against it is said only beyond this (a kind without such a model: the default)."""
        return LOAD_MODEL_TOLERANCE

    def eta_a(self, eta_o: np.ndarray | float) -> np.ndarray:
        """η_A from η_O by Eq. 3.4 with this actuator's gear ratio."""
        return eta_a_from_eta_o(eta_o, self.gear_ratio)

    def limits(self, parameter: str) -> list[tuple[float, Literal["above", "below"]]]:
        """The failure levels of ``parameter`` (FDJ, eta_O or eta_A), each with the way it is crossed: FDJ's upper
        one (default 1.5x nominal) and its lower one where the document gives it; η's lower one. None where the
        document gives no level and its nominal is not known (a ball screw's or a servo's before ema calibrate)."""
        if parameter == "FDJ":
            above = getattr(self.thresholds, self.facts.friction_field("fdj_above"))
            below = getattr(self.thresholds, self.facts.friction_field("fdj_below"))
            if above is None and self.nominal is not None:
                above = 1.5 * self.nominal.fdj
            levels: list[tuple[float, Literal["above", "below"]]] = [] if above is None else [(above, "above")]
            return levels + ([(below, "below")] if below is not None else [])
        eta_o = self.thresholds.eta_o_below
        if eta_o is None:  # the thesis's 0.70, or as far below a lower nominal (0.70 / 0.85 of it)
            if self.nominal is None or self.nominal.eta_o is None:
                return []
            eta_o = min(DEFAULT_ETA_O_BELOW, self.nominal.eta_o * DEFAULT_ETA_O_BELOW / THESIS_ETA_O)
        return [(eta_o if parameter == "eta_O" else float(self.eta_a(eta_o)), "below")]

    def threshold(self, parameter: str) -> tuple[float, Literal["above", "below"]]:
        """The first failure level of ``parameter`` (``limits``): FDJ's upper one, η's lower one."""
        found = self.limits(parameter)
        if not found:
            raise InputError(f"thresholds.{parameter}", "has no level: the document gives none and no nominal")
        return found[0]


KindDocument = TypeVar("KindDocument", bound=ActuatorDocument)


class RotaryActuator(ActuatorDocument):
    """A rotary actuator's document: a gear train to a surface, its drive simulated at 1 µs."""

    kind: Literal["rotary"] = Field("rotary", description=_KIND_DESCRIPTION)
    drive: Drive = Field(description="the drive and its gear train")
    nominal: RotaryNominal | None = Field(None, description="the health new: FDJ, FSJ and η_O")
    sensor_noise: SensorNoiseDocument | None = Field(None, description="null: the thesis's levels")
    airframe: Airframe | None = Field(None, description="null: the hinge moment is not checked against an aircraft")

    @property
    def section(self) -> Drive:
        return self.drive

    @property
    def nominal_class(self) -> type[Nominal]:
        return RotaryNominal

    @property
    def params(self) -> DriveConstants:
        return DriveConstants(**self.drive.model_dump())

    @property
    def load_model_tolerance(self) -> float:
        """The airframe's tolerance on its hinge-moment model (the default without an airframe)."""
        return LOAD_MODEL_TOLERANCE if self.airframe is None else self.airframe.tolerance

    @property
    def hinge(self) -> HingeGeometry | None:
        """The airframe's hinge-moment model, or None without an airframe."""
        if self.airframe is None:
            return None
        return HingeGeometry(**self.airframe.model_dump(exclude={"tolerance"}))

    @property
    def noise(self) -> SensorNoise:
        """The sensors' noise as the document gives it, else the thesis's levels."""
        return SensorNoise() if self.sensor_noise is None else SensorNoise(**self.sensor_noise.model_dump())


class LinearActuator(ActuatorDocument):
    """A linear actuator's document: a ball screw turned by a stepper."""

    kind: Literal["linear"] = Field(description=_KIND_DESCRIPTION)
    screw: Screw = Field(description="the screw and its drive")

    @property
    def section(self) -> Screw:
        return self.screw


class ServoActuator(ActuatorDocument):
    """A servo's document: a linear axis under a known position controller, logged on the load side."""

    kind: Literal["servo"] = Field(description=_KIND_DESCRIPTION)
    servo: Servo = Field(description="the drive, its controller and the load")

    @property
    def section(self) -> Servo:
        return self.servo


class GearedActuator(ActuatorDocument):
    """A geared servo's document: a DC motor, a gear train and its own position loop, logged at the output shaft."""

    kind: Literal["geared"] = Field(description=_KIND_DESCRIPTION)
    geared: Geared = Field(description="the motor, its gear train and its loop")

    @property
    def section(self) -> Geared:
        return self.geared


def as_kind(actuator: ActuatorDocument, kind: type[KindDocument]) -> KindDocument:
    """``actuator`` as ``kind``'s class (a kind's method reading its own section); InputError naming ``kind`` where
    the document is another kind's."""
    if not isinstance(actuator, kind):
        raise InputError("actuator.kind", f"is {actuator.kind}: this needs a {kind.__name__} document")
    return actuator


AnyActuator = Annotated[
    Annotated[RotaryActuator, Tag("rotary")]
    | Annotated[LinearActuator, Tag("linear")]
    | Annotated[ServoActuator, Tag("servo")]
    | Annotated[GearedActuator, Tag("geared")],
    tagged_by("kind", KIND_NAMES, DEFAULT_KIND),
]  # ``ema-actuator/1`` as read: one kind's document, by its ``kind``
ACTUATOR_DOCUMENT: TypeAdapter[ActuatorDocument] = TypeAdapter(AnyActuator)  # what parses and exports it


def _thesis() -> RotaryActuator:
    params, hinge = DriveConstants(), HingeGeometry()
    drive = {name: getattr(params, name) for name in Drive.model_fields}
    return RotaryActuator(
        name="thesis elevator EMA (Table 3.1)",
        drive=Drive(**drive),
        nominal=RotaryNominal(fdj_nm=0.05, fsj_nm=0.10, eta_o=0.85),
        thresholds=Thresholds(fdj_above_nm=0.075, eta_o_below=0.70),
        airframe=Airframe(**{name: getattr(hinge, name) for name in Airframe.model_fields if name != "tolerance"}),
    )


THESIS = _thesis()


def actuator_from_dict(document: Any) -> ActuatorDocument:
    """Parse and validate an ``ema-actuator/1`` document (a dict) as its kind's class; errors name the field."""
    return validated(ACTUATOR_DOCUMENT, document, "actuator", tags=KIND_NAMES)


def actuator_from_json(text: str | bytes) -> ActuatorDocument:
    """An ``ema-actuator/1`` document from its JSON text (a stored one), as its kind's class."""
    return ACTUATOR_DOCUMENT.validate_json(text)


def actuator_schema(ref_template: str = DEFAULT_REF_TEMPLATE) -> dict[str, Any]:
    """The JSON Schema of ``ema-actuator/1``: one kind's document, chosen by ``kind``."""
    return {"title": "ActuatorDocument", **ACTUATOR_DOCUMENT.json_schema(by_alias=True, ref_template=ref_template)}


def read_actuator(path: str | Path) -> ActuatorDocument:
    """Read an ``ema-actuator/1`` JSON file; a bad file raises InputError naming it and the field."""
    return read_document(path, actuator_from_dict)
