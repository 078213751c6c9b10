"""Actuator constants (thesis Table 3.1), health parameters, their ranges and Eq. 3.4."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from ema.model.checks import InputError, array_in_range, finite_array

MAX_CORRELATION_S = 0.1  # a sensor noise's correlation time: far beyond any filter; a longer "noise" is signal


@dataclass(frozen=True)
class DriveConstants:
    """Constants of the EMA; every value is SI and reduced as the comment says."""

    position_gain_per_s: float = 1e5  # G_P [1/s]: user-angle error [rad] -> motor speed reference [rad/s]
    speed_gain_nms: float = 5e-2  # GAP [N·m·s/rad]: speed error -> torque reference
    resistance_ohm: float = 2.13  # R [Ω], equivalent phase
    inductance_h: float = 7.2e-4  # L [H], equivalent phase
    torque_constant_nm_per_a: float = 0.0752  # k_T = k_e [N·m/A = V·s/rad]
    max_motor_torque_nm: float = 1.689  # T_M,max [N·m], magnetic saturation
    supply_voltage_v: float = 48.0  # V_max [V]
    max_current_a: float = 22.5  # I_max [A], current reference saturation
    gear_ratio: float = 500.0  # n [-], motor speed / elevator speed
    inertia_kgm2: float = 2.5e-5  # J_M [kg·m²], total, reduced to the motor shaft
    viscous_nms: float = 5.172e-5  # C_M [N·m·s/rad] at the motor shaft
    backlash_rad: float = 5e-3  # BLK [rad], total dead-band width on the elevator side
    end_stop_deg: float = 30.0  # θ_stop [deg], symmetric mechanical end stops
    step_s: float = 1e-6  # h [s], integration step of the electrical and mechanical loop

    @property
    def max_motor_speed_radps(self) -> float:
        """ω_max = V_max / k_e [rad/s], the speed-reference saturation."""
        return self.supply_voltage_v / self.torque_constant_nm_per_a


def eta_a_from_eta_o(eta_o: np.ndarray | float, gear_ratio: float) -> np.ndarray:
    """Aiding efficiency from opposing efficiency, thesis Eq. 3.4 with τ = n."""
    return eta_a_of(np.asarray(eta_o, dtype=np.float64), gear_ratio)


def eta_a_of(eta_o: Any, n: float) -> Any:
    """Eq. 3.4 itself, η_A = (2n²η_O − n² + n) / (n²η_O + n − η_O + 1), on scalars or arrays (and compiled in
    ``ema.kinds.rotary.physics.eta_search``)."""
    return (2 * n * n * eta_o - n * n + n) / (n * n * eta_o + n - eta_o + 1)


def load_factors(eta_o: Any, gear_ratio: float) -> tuple[Any, Any]:
    """(k_aid, k_opp) of Eq. 5.1 at η_O: what a load adds to the friction per N·m, aiding (1 − η_A, Eq. 3.4) and
    opposing (1/η_O − 1); on scalars or arrays, and the one definition the simulator, the solutions and the calibration
    use."""
    return 1.0 - eta_a_of(eta_o, gear_ratio), 1.0 / eta_o - 1.0


@dataclass(frozen=True)
class HealthRanges:
    """Nominal values and sampling ranges of the health parameters (thesis §5.4, Table 3.1)."""

    fsj_nm: tuple[float, float] = (0.08, 0.12)  # FSJ [N·m], static friction at the motor shaft
    fdj_nm: tuple[float, float] = (0.04, 0.06)  # FDJ [N·m], dynamic friction at the motor shaft
    eta_o: tuple[float, float] = (0.68, 0.98)  # η_O [-], efficiency under opposing load (capped below 1)
    nominal_fsj_nm: float = 0.10  # FSJ [N·m] of a healthy actuator
    nominal_fdj_nm: float = 0.05  # FDJ [N·m] of a healthy actuator
    nominal_eta_o: float = 0.85  # η_O [-] of a healthy actuator

    def of(self, name: str) -> tuple[float, float]:
        """The healthy range of the estimate ``name`` (``FDJ`` or ``eta_O``), in its unit."""
        return self.fdj_nm if name == "FDJ" else self.eta_o

    def __post_init__(self) -> None:
        for name in ("fsj_nm", "fdj_nm", "eta_o"):
            low, high = getattr(self, name)
            if not 0.0 < low < high:
                raise InputError(name, f"range must satisfy 0 < low < high, got ({low}, {high})")
            nominal = getattr(self, f"nominal_{name}")
            if not low <= nominal <= high:
                raise InputError(f"nominal_{name}", f"{nominal} lies outside its range ({low}, {high})")
        if self.eta_o[1] > 1.0:
            raise InputError("eta_o", "efficiency under opposing load cannot exceed 1")


# Case 1A/1B ranges (Table 3.1 nominal ±20 %, η_O capped below 1) and Case 1C (η_O nominal 0.55).
DEFAULT_RANGES = HealthRanges()
IRREVERSIBLE_RANGES = HealthRanges(eta_o=(0.44, 0.66), nominal_eta_o=0.55)


@dataclass(frozen=True)
class HealthParams:
    """One value per simulation of each health parameter (arrays of equal length)."""

    fsj_nm: np.ndarray  # FSJ [N·m]
    fdj_nm: np.ndarray  # FDJ [N·m]
    eta_o: np.ndarray  # η_O [-]

    def __post_init__(self) -> None:
        arrays = {name: finite_array(name, getattr(self, name), ndim=1) for name in ("fsj_nm", "fdj_nm", "eta_o")}
        lengths = {len(a) for a in arrays.values()}
        if len(lengths) != 1 or 0 in lengths:
            raise InputError("health", f"fsj_nm, fdj_nm and eta_o need one equal, non-zero length, got {lengths}")
        array_in_range("fsj_nm", arrays["fsj_nm"], 0.0, 10.0, "N·m")
        array_in_range("fdj_nm", arrays["fdj_nm"], 0.0, 10.0, "N·m")
        array_in_range("eta_o", arrays["eta_o"], 1e-3, 1.0)
        for name, array in arrays.items():
            object.__setattr__(self, name, array)

    def __len__(self) -> int:
        return len(self.fdj_nm)

    def identical(self, other: HealthParams) -> bool:
        """Whether ``other`` holds exactly these values: the same simulations, to the bit."""
        return all(np.array_equal(getattr(self, f.name), getattr(other, f.name)) for f in fields(self))

    def eta_a(self, gear_ratio: float) -> np.ndarray:
        """η_A by Eq. 3.4."""
        return eta_a_from_eta_o(self.eta_o, gear_ratio)

    @classmethod
    def uniform(cls, n: int, ranges: HealthRanges, rng: np.random.Generator) -> HealthParams:
        """``n`` independent draws, each parameter uniform over its range (FSJ sampled even when not a target)."""
        if n < 1:
            raise InputError("n_simulations", f"must be at least 1, got {n}")
        return cls(
            fsj_nm=rng.uniform(*ranges.fsj_nm, size=n),
            fdj_nm=rng.uniform(*ranges.fdj_nm, size=n),
            eta_o=rng.uniform(*ranges.eta_o, size=n),
        )

    @classmethod
    def single(cls, fsj_nm: float = 0.10, fdj_nm: float = 0.05, eta_o: float = 0.85) -> HealthParams:
        """One simulation's parameters (thesis nominal by default)."""
        return cls(fsj_nm=np.array([fsj_nm]), fdj_nm=np.array([fdj_nm]), eta_o=np.array([eta_o]))
