"""A geared servo's part of ``ema-actuator/1``: a DC motor fed by PWM from its supply, a gear train, and its own
proportional position loop, logged at the output shaft (angles in rad, torques in N·m at the output), swinging a
load whose mass and arm each log records.

Once per logged sample of length Δt, the firmware reads the position q against the set point r (reaching it
``command_delay_s`` late) and applies the duty

    d = clip(kp·g·(r − q) + d₀·sgn(r − q), ±d_max)

(kp the log's gain, g ``error_gain_per_rad``, d₀ ``min_duty``, d_max ``duty_limit``). The motor, fed d·V from the
logged supply V, gives at the output τ_m = (k_t/R)·d·V − (k_t²/R)·q̇ (zero where the log says the motor is off).
The load, a point mass m at the arm's end l with the arm's own mass along it, pulls τ_g = −(m·l + μ·l²/2)·g·sin q
(q = 0 hanging down) and adds m·l² + μ·l³/3 to the servo's own inertia J. The gear train's friction is the thesis's
Borello model: FDJ + (1/η_O − 1)·|τ_g| where the load opposes the motion, FDJ + (1 − η_A)·|τ_g| where it aids it,
plus C·|q̇|; it holds the shaft where it can (``docs/model.md`` gives the step). What ``ema calibrate`` learns fills
the nulls; the nominal health (FDJ, η_O, η_A) sits in the document's ``nominal``.
"""

from __future__ import annotations

from typing import Any

from pydantic import Field, field_validator

from ema.model.document import Document, Number

GEARED_EFFECTS = ("efficiency", "command_delay", "min_duty", "static_friction")
# what calibration may adopt into the model (``ema.kinds.geared.effects`` says what each is)
GEARED_CONSTANTS = ("position_gain", "load_mass_kg", "arm_length_m")  # what each log records beside its signals
LEARNED = (
    "torque_constant_nm_per_a",
    "resistance_ohm",
    "inertia_kg_m2",
    "error_gain_per_rad",
    "duty_limit",
    "viscous_nm_s_per_rad",
    "command_delay_s",
    "min_duty",
    "static_friction_ratio",
)  # the section's constants ema calibrate learns, each with its std in ``stds``


class Geared(Document):
    """The motor, its gear train and its position loop, at the output shaft."""

    gear_ratio: Number = Field(gt=1, le=1e5, description="the motor's turns per output turn (η_A's Eq. 3.4 with it)")
    position_resolution_rad: Number | None = Field(
        None, gt=0, le=0.1, description="the output encoder's step (2π over its counts a turn); null: read from the log"
    )
    torque_constant_nm_per_a: Number | None = Field(
        None, gt=0, le=1e3, description="k_t at the output shaft (its back-EMF constant, V·s/rad, alike) (learned)"
    )
    resistance_ohm: Number | None = Field(None, gt=0, le=1e4, description="R, the winding's (learned)")
    inertia_kg_m2: Number | None = Field(
        None, gt=0, le=1e3, description="J, the servo's own inertia at the output, its rotor's included (learned)"
    )
    error_gain_per_rad: Number | None = Field(
        None, gt=0, le=1e3, description="g: duty per rad of position error per unit of the log's gain kp (learned)"
    )
    duty_limit: Number = Field(0.97, gt=0, le=1, description="d_max, the firmware's duty saturation (learned)")
    viscous_nm_s_per_rad: Number | None = Field(None, ge=0, le=1e3, description="C, the gear train's (learned)")
    command_delay_s: Number = Field(
        0.0, ge=0, le=0.5, description="how late the logged set point reaches the loop (an adopted effect's)"
    )
    min_duty: Number = Field(0.0, ge=0, lt=0.5, description="d₀, the firmware's minimum duty (an adopted effect's)")
    static_friction_ratio: Number = Field(
        1.0, ge=1, le=10, description="FSD: the friction that holds a shaft at rest over the sliding one (adopted)"
    )
    arm_kg_per_m: Number = Field(
        0.0, ge=0, le=100, description="μ, the arm's own mass per metre from the axis (0: a massless arm)"
    )
    position_error_rad: Number | None = Field(
        None,
        ge=0,
        le=10,
        description="the calibrated model's mean |position error| on runs it did not see: how far a healthy run "
        "lies from its simulation, the check's floor (learned)",
    )
    effects: dict[str, Number] = Field(
        default_factory=dict,
        description="the effects ema calibrate adopted into this servo's model, 1 each: any of "
        f"{', '.join(GEARED_EFFECTS)}",
    )
    stds: dict[str, Number] = Field(
        default_factory=dict, description="each learned constant's std, by its field's name (and fdj_nm, eta_o, eta_a)"
    )
    repeatability: dict[str, Number] = Field(
        default_factory=dict,
        description="how far one run's reading of FDJ (fdj_nm), η_O (eta_o) and η_A (eta_a) scatters about the "
        "nominal beyond its own std: what a run of this healthy servo reads (learned)",
    )

    @field_validator("effects")
    @classmethod
    def _known_effects(cls, effects: dict[str, float]) -> dict[str, float]:
        unknown = sorted(set(effects) - set(GEARED_EFFECTS))
        if unknown:
            raise ValueError(f"{unknown[0]} is not an effect of a geared servo's model ({', '.join(GEARED_EFFECTS)})")
        return effects

    @field_validator("stds", "repeatability")
    @classmethod
    def _non_negative(cls, values: dict[str, float]) -> dict[str, float]:
        negative = sorted(name for name, value in values.items() if value < 0)
        if negative:
            raise ValueError(f"{negative[0]}: a std is never negative")
        return values

    def missing(self) -> list[str]:
        """The constants a window cannot be simulated without, that neither the document nor ema calibrate gave."""
        needed = ("torque_constant_nm_per_a", "resistance_ohm", "inertia_kg_m2", "error_gain_per_rad")
        return [name for name in needed if getattr(self, name) is None] + (
            ["viscous_nm_s_per_rad"] if self.viscous_nm_s_per_rad is None else []
        )

    def completed(self, **learned: Any) -> Geared:
        """This section with ``learned`` constants in (a calibration's)."""
        return type(self).model_validate({**self.model_dump(), **learned})
