"""A rotary actuator's part of ``ema-actuator/1``: its drive's constants (current, speed and position loops,
motor, gear train), under the simulator's names (``ema.model.params.DriveConstants``)."""

from __future__ import annotations

from pydantic import Field, model_validator

from ema.model.document import Document, Number
from ema.model.params import DriveConstants

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
