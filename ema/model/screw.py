"""A linear actuator's part of ``ema-actuator/1``: the ball screw its motor turns, and what its drive's current says."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from ema.model.document import Document, Number


class Screw(Document):
    """A linear actuator: a ball screw turned by its motor, and what the drive's logged current says of the motor's
    torque. A stepper's drive is no current loop ema can simulate: its current per N·m and its current at zero
    torque are on no data sheet, and ``ema calibrate`` learns them from healthy runs at two loads."""

    lead_mm: Number = Field(gt=0, le=1000, description="the screw's lead: travel per motor revolution [mm]")
    motor: Literal["stepper"] = Field(
        "stepper", description="the drive (a stepper: its current is read quasi-statically)"
    )
    holding_torque_nm: Number | None = Field(None, gt=0, le=1e4, description="the motor's holding torque (data sheet)")
    current_per_nm_a: Number | None = Field(
        None,
        gt=0,
        le=1e3,
        description="c: drive current per N·m of motor torque along the motion (null: not yet learned)",
    )
    current_per_nm_std_a: Number | None = Field(None, ge=0, le=1e3, description="its std as learned")
    current_at_zero_torque_a: Number | None = Field(
        None,
        ge=0,
        le=1e3,
        description="I0: the current that holds the motor with no torque; a window at rest reads its own",
    )
    current_at_zero_torque_std_a: Number | None = Field(
        None, ge=0, le=1e3, description="I0's spread from one day to the next, for a window that never rests"
    )
    eta_o_std: Number | None = Field(None, ge=0, lt=1, description="the std of the nominal η_O as learned")
    repeatability_nm: Number | None = Field(
        None,
        ge=0,
        le=100,
        description="the run-to-run std of FDJ beyond each run's own noise, over every load as learned (documents "
        "learned before run_to_run_nm was kept)",
    )
    run_to_run_nm: Number | None = Field(
        None, ge=0, le=100, description="the sd of one healthy run's FDJ within a set of one load, as learned"
    )
    run_noise_nm: Number | None = Field(
        None, ge=0, le=100, description="the typical std of one healthy run's own noise, as learned"
    )
    healthy_set_nm: Number | None = Field(
        None,
        ge=0,
        le=100,
        description="how far a healthy set's mean FDJ sits off the nominal (its loads, its day), as learned",
    )
    calibrated_loads_n: list[Annotated[Number, Field(ge=-1e6, le=1e6)]] | None = Field(
        None,
        description="the loads [N] the healthy runs were learned at, signed as load_n (beyond them the nominal "
        "extrapolates)",
    )
    stroke_profile_a: list[list[Number]] | None = Field(
        None, description="the healthy runs' current along each stroke (up, then down; less its mean), binned"
    )
    stroke_profile_std_a: list[list[Annotated[Number, Field(ge=0)]]] | None = Field(
        None, description="the healthy runs' run-to-run std of that current, per bin (null: not learned)"
    )

    @property
    def gear_ratio(self) -> float:
        """Motor radians per metre of travel, 2π/lead: the screw's transmission ratio in Eq. 3.4."""
        return 2.0 * np.pi / (self.lead_mm / 1000.0)

    def load_torque_nm(self, force_n: np.ndarray | float) -> np.ndarray:
        """The load force as a torque at the motor, F·lead/2π."""
        return np.asarray(force_n) * (self.lead_mm / 1000.0) / (2.0 * np.pi)
