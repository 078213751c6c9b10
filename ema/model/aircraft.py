"""F-16 linear longitudinal dynamics, its scaling over the envelope, exact discretization, hinge moment.

Numbers and scaling rules: ``docs/model.md`` (Stevens & Lewis Example 4.4-1, SI).
The kernel sees the aircraft only through a :class:`LoadModel`: a discrete linear system advanced
once per log interval plus the hinge-moment output, so the on-ground case (a prescribed load) and
a load taken from a log are the same structure with the dynamics switched off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ema.model.checks import in_range
from ema.model.envelope import AIRSPEED_RANGE_MPS, ALTITUDE_RANGE_M, DEFAULT_AIRSPEED_MPS

GRAVITY_MPS2 = 9.80665
SEA_LEVEL_DENSITY_KGPM3 = 1.2250


@dataclass(frozen=True)
class HingeGeometry:
    """Elevator hinge-moment model, sized to the thesis's EMA (``docs/model.md``)."""

    area_m2: float = 0.34  # S_e [m²], one elevator half
    chord_m: float = 0.25  # c_e [m]
    ch0: float = 0.0  # C_h0 [-]
    ch_alpha_per_rad: float = -0.25  # C_hα [1/rad]
    ch_delta_per_rad: float = -0.55  # C_hδ [1/rad]
    downwash_gradient: float = 0.4  # dε/dα [-]
    tail_arm_m: float = 4.6  # l_t [m]
    alpha_t_limit_rad: float = float(np.radians(15.0))  # |α_t| saturation [rad]

    def scale_nm(self, condition: FlightCondition) -> float:
        """q̄·S_e·c_e [N·m]: the moment per unit of hinge-moment coefficient at ``condition``."""
        return condition.dynamic_pressure_pa * self.area_m2 * self.chord_m

    def per_deflection_nm_per_rad(self, condition: FlightCondition) -> float:
        """q̄·S_e·c_e·C_hδ [N·m/rad]: the part of the moment that follows the deflection at ``condition``."""
        return self.scale_nm(condition) * self.ch_delta_per_rad


@dataclass(frozen=True)
class FlightCondition:
    """Where the aircraft flies; validated against the model's envelope."""

    airspeed_mps: float = DEFAULT_AIRSPEED_MPS  # true airspeed V [m/s]
    altitude_m: float = 0.0  # pressure altitude h [m], ISA troposphere

    def __post_init__(self) -> None:
        in_range("flight_condition.airspeed_mps", self.airspeed_mps, *AIRSPEED_RANGE_MPS, "m/s")
        in_range("flight_condition.altitude_m", self.altitude_m, *ALTITUDE_RANGE_M, "m")

    @property
    def density_kgpm3(self) -> float:
        """ISA troposphere density ρ(h)."""
        return SEA_LEVEL_DENSITY_KGPM3 * (1.0 - 2.2558e-5 * self.altitude_m) ** 4.2559

    @property
    def density_ratio(self) -> float:
        """ρ(h)/ρ0: what the sea-level linearization and trim table are scaled by."""
        return self.density_kgpm3 / SEA_LEVEL_DENSITY_KGPM3

    @property
    def dynamic_pressure_pa(self) -> float:
        """q̄ = ½ρV²."""
        return 0.5 * self.density_kgpm3 * self.airspeed_mps**2
