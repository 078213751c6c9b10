"""Optional physical effects the base model lacks, off by default.

Each effect is a few named parameters whose neutral values leave the base model exactly as it
is; the kernel reads them from its constants (see ``simulator.kernels.advance``), so switching an
effect on is a parameter change, never a fork of the kernel. Beside the named effects, a
:class:`FrictionTable` adds dry friction of any shape against motor speed, elevator position or
time: the data-driven term the calibration loop offers when no named effect matches.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from ema.model.checks import InputError, in_range


@dataclass(frozen=True)
class Effect:
    """One optional effect: its parameters with neutral value and bounds."""

    name: str
    parameters: Mapping[str, tuple[float, float, float]]  # name -> (neutral, low, high)


EFFECTS: Mapping[str, Effect] = MappingProxyType(
    {
        effect.name: effect
        for effect in (
            Effect(
                "viscous",
                {"coefficient_nms": (0.0, -5e-5, 5e-3)},  # extra viscous coefficient [N·m·s/rad], motor shaft
            ),
            Effect(
                "stribeck",
                {
                    "amplitude_nm": (0.0, -0.1, 1.0),  # extra dry friction at zero speed [N·m]
                    "speed_radps": (20.0, 0.5, 300.0),  # speed where half of it is left [rad/s]
                },
            ),
            Effect(
                "torque_constant",
                {"gain": (1.0, 0.7, 1.3)},  # true k_T = k_e over the nominal [-]
            ),
            Effect(
                "hinge_moment_bias",
                {"bias_nm": (0.0, -500.0, 500.0)},  # offset of the hinge-moment sensor [N·m]
            ),
            Effect(
                "current_sensor_gain",
                {"gain": (1.0, 0.7, 1.3)},  # measured current over true current [-] (the loop sees it)
            ),
            Effect(
                "current_sensor_offset",
                {"offset_a": (0.0, -5.0, 5.0)},  # measured − gain × true current [A] (the loop sees it)
            ),
            Effect(
                "position_friction",
                {"amplitude_nm": (0.0, -0.05, 1.0)},  # extra dry friction at full deflection [N·m], ∝ |θ_u|
            ),
            Effect(
                "cogging",
                {
                    "amplitude_nm": (0.0, 0.0, 0.5),  # cogging torque amplitude [N·m]
                    "periods_per_rev": (6.0, 1.0, 48.0),  # ripple periods per motor revolution [-]
                    "phase_rad": (0.0, -4.0, 4.0),  # A·sin(p·θ_m + φ), θ_m from n·θ_u at the window's start
                },
            ),
            Effect(
                "inertia",
                {"factor": (1.0, 0.5, 2.0)},  # true J_M over the nominal [-] (a rotor, screw and gears reflected)
            ),
            Effect(
                "backlash",
                {"extra_rad": (0.0, -5e-3, 0.1)},  # backlash beyond the nominal BLK [rad], elevator side
            ),
        )
    }
)


TABLE_VARIABLES = {"speed": 1, "position": 2, "time": 3}  # |ω_m| [rad/s], θ_u [rad], t [s]; kernel codes
MAX_TABLE_NM = 0.5


@dataclass(frozen=True)
class FrictionTable:
    """Extra dry friction [N·m] (dynamic and static alike) tabulated on a uniform grid of one variable."""

    variable: str  # "speed" (|ω_m| [rad/s]), "position" (θ_u [rad]) or "time" (from the window's start [s])
    start: float  # first grid point, in the variable's unit
    step: float  # grid spacing, > 0
    values_nm: tuple[float, ...]  # friction at the grid points; linear between, held past the ends

    def __post_init__(self) -> None:
        if self.variable not in TABLE_VARIABLES:
            raise InputError("table.variable", f"must be one of {', '.join(TABLE_VARIABLES)}, got {self.variable!r}")
        in_range("table.step", self.step, 1e-9, 1e6)
        in_range("table.start", self.start, -1e6, 1e6)
        if not 2 <= len(self.values_nm) <= 1000:
            raise InputError("table.values_nm", f"needs 2..1000 values, got {len(self.values_nm)}")
        values = tuple(in_range("table.values_nm", v, -MAX_TABLE_NM, MAX_TABLE_NM, "N·m") for v in self.values_nm)
        object.__setattr__(self, "values_nm", values)


@dataclass(frozen=True)
class EffectSet:
    """The effects switched on, with their parameters, and a friction table; empty means the base model."""

    values: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    table: FrictionTable | None = None

    def __post_init__(self) -> None:
        checked: dict[str, dict[str, float]] = {}
        for name, parameters in self.values.items():
            if name not in EFFECTS:
                raise InputError("effects", f"unknown effect {name!r}; known: {', '.join(EFFECTS)}")
            spec = EFFECTS[name].parameters
            unknown = set(parameters) - set(spec)
            if unknown:
                raise InputError(f"effects.{name}", f"unknown parameter(s) {sorted(unknown)}; known: {sorted(spec)}")
            checked[name] = {
                key: in_range(f"effects.{name}.{key}", parameters.get(key, neutral), low, high)
                for key, (neutral, low, high) in spec.items()
            }
        object.__setattr__(self, "values", MappingProxyType(checked))

    def get(self, effect: str, parameter: str) -> float:
        """The value in force: the one given, or the neutral one."""
        if effect in self.values:
            return self.values[effect][parameter]
        return EFFECTS[effect].parameters[parameter][0]

    def with_effect(self, effect: str, **parameters: float) -> EffectSet:
        """A copy with ``effect`` switched on (or replaced)."""
        return EffectSet({**self.values, effect: parameters}, self.table)

    @classmethod
    def combined(cls, sets: Iterable[EffectSet]) -> EffectSet:
        """Every effect of ``sets`` together (a later set's parameters win for an effect in two), and one friction
        table: the first (the simulator adds one)."""
        values: dict[str, dict[str, float]] = {}
        table = None
        for effects in sets:
            values.update(effects.as_dict())
            table = table or effects.table
        return cls(values, table)

    def with_table(self, table: FrictionTable | None) -> EffectSet:
        return EffectSet(self.values, table)

    def as_dict(self) -> dict[str, dict[str, float]]:
        return {name: dict(parameters) for name, parameters in self.values.items()}
