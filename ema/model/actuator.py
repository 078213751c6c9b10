"""``ema-actuator/1``: one actuator of the architecture (position, speed and current loops, gearbox, Borello
friction, backlash, end stops) with its own constants, as its user writes it down.

:class:`Actuator` is the document and what every stage reads its constants from: the drive's constants
(``params``: the simulator's :class:`~ema.model.params.DriveConstants`, same field names), the nominal health and
the healthy range around it (``ranges``), the prognosis's failure levels (``thresholds``), and optionally
the sensors' noise and the airframe the hinge moment is checked against. ``THESIS`` is the thesis's
elevator EMA (Table 3.1), the default wherever a user names none; ``examples/actuator.json`` holds it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from ema.model.aircraft import HingeGeometry
from ema.model.checks import InputError, read_document, validated
from ema.model.document import Document, Number
from ema.model.params import MAX_CORRELATION_S, DriveConstants, HealthRanges, eta_a_from_eta_o
from ema.model.screw import Screw

if TYPE_CHECKING:
    from ema.model.noise import SensorNoise

SCHEMA = "ema-actuator/1"
DEFAULT_ETA_O_BELOW, THESIS_ETA_O = 0.70, 0.85  # the prognosis's default η_O threshold, at the thesis's nominal
HEALTHY_SPAN = 0.2  # the healthy range: nominal ±20 % (η_O capped below 1), the thesis's §5.4 ranges
MAX_HEALTHY_ETA_O = 0.98
STEP_S = DriveConstants().step_s  # the simulator's 1 µs step: the current loop must be stable at it


class Drive(Document):
    """The drive's constants, under the simulator's names (units in the names)."""

    position_gain_per_s: Number = Field(gt=0, le=1e7, description="G_P: elevator angle error [rad] -> speed ref")
    speed_gain_nms: Number = Field(gt=0, le=100, description="GAP: speed error -> torque reference")
    resistance_ohm: Number = Field(gt=0, le=1e3, description="R, equivalent phase")
    inductance_h: Number = Field(gt=0, le=10, description="L, equivalent phase")
    torque_constant_nm_per_a: Number = Field(gt=0, le=100, description="k_T = k_e")
    max_motor_torque_nm: Number = Field(gt=0, le=1e4, description="T_M,max, magnetic saturation")
    supply_voltage_v: Number = Field(gt=0, le=1e4, description="V_max")
    max_current_a: Number = Field(gt=0, le=1e4, description="I_max, current reference saturation")
    gear_ratio: Number = Field(ge=1, le=1e5, description="n: motor speed / elevator speed")
    inertia_kgm2: Number = Field(gt=0, le=10, description="J_M, total, reduced to the motor shaft")
    viscous_nms: Number = Field(ge=0, le=10, description="C_M at the motor shaft")
    backlash_rad: Number = Field(ge=0, le=0.2, description="BLK, total dead band on the elevator side")
    end_stop_deg: Number = Field(gt=0, le=90, description="θ_stop, symmetric mechanical end stops")

    @model_validator(mode="after")
    def _stable_current_loop(self) -> Drive:
        if self.resistance_ohm / self.inductance_h * STEP_S >= 1.0:
            raise ValueError(
                f"inductance_h: R/L = {self.resistance_ohm / self.inductance_h:g}/s; the current loop "
                f"integrates at {STEP_S:g} s and needs R/L below {1 / STEP_S:g}/s"
            )
        return self


class Nominal(Document):
    """The health of this actuator new."""

    fdj_nm: Number = Field(gt=0, le=100, description="FDJ, dynamic friction at the motor shaft")
    fsj_nm: Number | None = Field(
        None, gt=0, le=100, description="FSJ, static (break-away) friction at the motor shaft (a rotary actuator's)"
    )
    eta_o: Number = Field(gt=0, lt=1, description="η_O, efficiency under opposing load")

    @model_validator(mode="after")
    def _static_at_least_dynamic(self) -> Nominal:
        if self.fsj_nm is not None and self.fsj_nm < self.fdj_nm:
            raise ValueError(
                f"fsj_nm: {self.fsj_nm:g} is below fdj_nm {self.fdj_nm:g}: static friction is never below dynamic"
            )
        return self


class Thresholds(Document):
    """Where each parameter ends the actuator's useful life (the prognosis's failure levels)."""

    fdj_above_nm: Number | None = Field(None, gt=0, le=100, description="default: 1.5x the nominal FDJ")
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


class ActuatorDocument(Document):
    """``ema-actuator/1``."""

    schema_: Literal["ema-actuator/1"] = Field("ema-actuator/1", alias="schema")
    name: str = Field(min_length=1, max_length=200, description="for a person")
    kind: Literal["rotary", "linear"] = Field(
        "rotary", description="rotary: a gear train to a surface (drive); linear: a ball screw (screw)"
    )
    drive: Drive | None = Field(None, description="a rotary actuator's drive and gear train")
    screw: Screw | None = Field(None, description="a linear actuator's screw and drive")
    nominal: Nominal | None = Field(
        None, description="the health new; a linear actuator's is learned by ema calibrate on healthy runs"
    )
    thresholds: Thresholds = Field(default_factory=Thresholds)
    sensor_noise: SensorNoiseDocument | None = Field(None, description="null: the thesis's levels")
    airframe: Airframe | None = Field(None, description="null: the hinge moment is not checked against an aircraft")

    @model_validator(mode="after")
    def _one_kind(self) -> ActuatorDocument:
        needed, other = ("drive", "screw") if self.kind == "rotary" else ("screw", "drive")
        if getattr(self, needed) is None:
            raise ValueError(f"{needed}: a {self.kind} actuator's document gives its {needed}")
        if getattr(self, other) is not None:
            raise ValueError(f"{other}: a {self.kind} actuator has no {other} (kind: {self.kind})")
        if self.kind == "rotary" and (self.nominal is None or self.nominal.fsj_nm is None):
            raise ValueError("nominal.fsj_nm: a rotary actuator's document gives its nominal FDJ, FSJ and η_O")
        return self

    @model_validator(mode="after")
    def _thresholds_past_nominal(self) -> ActuatorDocument:
        if self.nominal is None:
            return self
        fdj, eta = self.threshold("FDJ")[0], self.threshold("eta_O")[0]
        if fdj <= self.nominal.fdj_nm:
            raise ValueError(f"thresholds.fdj_above_nm: {fdj:g} is not above the nominal FDJ {self.nominal.fdj_nm:g}")
        if eta >= self.nominal.eta_o:
            raise ValueError(f"thresholds.eta_o_below: {eta:g} is not below the nominal η_O {self.nominal.eta_o:g}")
        return self

    @property
    def params(self) -> DriveConstants:
        """The drive's constants as the simulator takes them (a rotary actuator's)."""
        assert self.drive is not None, "a linear actuator has no simulator constants"
        return DriveConstants(**self.drive.model_dump())

    @property
    def gear_ratio(self) -> float:
        """Motor speed over output speed: a gear train's n, a screw's 2π/lead [rad/m]."""
        if self.screw is not None:
            return self.screw.gear_ratio
        assert self.drive is not None
        return self.drive.gear_ratio

    @property
    def health(self) -> Nominal:
        """The nominal health; InputError where a linear actuator's is not learned yet."""
        if self.nominal is None:
            raise InputError(
                "actuator.nominal",
                "is not known yet: run ema calibrate on healthy runs at two loads "
                "and read with the document it writes (--out-actuator)",
            )
        return self.nominal

    @property
    def ranges(self) -> HealthRanges:
        """The healthy range around the nominal health: ``HEALTHY_SPAN`` either way, η_O capped below 1."""
        n, span = self.health, HEALTHY_SPAN
        fsj = n.fsj_nm if n.fsj_nm is not None else n.fdj_nm
        eta = (n.eta_o * (1 - span), min(n.eta_o * (1 + span), max(MAX_HEALTHY_ETA_O, n.eta_o)))
        return HealthRanges(
            fsj_nm=(fsj * (1 - span), fsj * (1 + span)),
            fdj_nm=(n.fdj_nm * (1 - span), n.fdj_nm * (1 + span)),
            eta_o=eta,
            nominal_fsj_nm=fsj,
            nominal_fdj_nm=n.fdj_nm,
            nominal_eta_o=n.eta_o,
        )

    def eta_a(self, eta_o: np.ndarray | float) -> np.ndarray:
        """η_A from η_O by Eq. 3.4 with this actuator's gear ratio."""
        return eta_a_from_eta_o(eta_o, self.gear_ratio)

    def threshold(self, parameter: str) -> tuple[float, Literal["above", "below"]]:
        """The failure level of ``parameter`` (FDJ, eta_O or eta_A) and the way it is crossed."""
        eta_o = self.thresholds.eta_o_below
        if eta_o is None:  # the thesis's 0.70, or as far below a lower nominal (0.70 / 0.85 of it)
            eta_o = min(DEFAULT_ETA_O_BELOW, self.health.eta_o * DEFAULT_ETA_O_BELOW / THESIS_ETA_O)
        if parameter == "FDJ":
            fdj = self.thresholds.fdj_above_nm
            return (fdj if fdj is not None else 1.5 * self.health.fdj_nm), "above"
        if parameter == "eta_O":
            return eta_o, "below"
        return float(self.eta_a(eta_o)), "below"

    @property
    def hinge(self) -> HingeGeometry | None:
        """The airframe's hinge-moment model, or None without an airframe."""
        if self.airframe is None:
            return None
        return HingeGeometry(**self.airframe.model_dump(exclude={"tolerance"}))

    @property
    def noise(self) -> SensorNoise:
        """The sensors' noise as the document gives it, else the thesis's levels."""
        from ema.model.noise import SensorNoise  # Numba's: kept out of the document's import (clients read it)

        return SensorNoise() if self.sensor_noise is None else SensorNoise(**self.sensor_noise.model_dump())


def _thesis() -> ActuatorDocument:
    params, hinge = DriveConstants(), HingeGeometry()
    drive = {name: getattr(params, name) for name in Drive.model_fields}
    return ActuatorDocument(
        name="thesis elevator EMA (Table 3.1)",
        drive=Drive(**drive),
        nominal=Nominal(fdj_nm=0.05, fsj_nm=0.10, eta_o=0.85),
        thresholds=Thresholds(fdj_above_nm=0.075, eta_o_below=0.70),
        airframe=Airframe(**{name: getattr(hinge, name) for name in Airframe.model_fields if name != "tolerance"}),
    )


THESIS = _thesis()


def actuator_from_dict(document: Any) -> ActuatorDocument:
    """Parse and validate an ``ema-actuator/1`` document (a dict); errors name the field."""
    return validated(ActuatorDocument, document, "actuator")


def read_actuator(path: str | Path) -> ActuatorDocument:
    """Read an ``ema-actuator/1`` JSON file; a bad file raises InputError naming it and the field."""
    return read_document(path, actuator_from_dict)
