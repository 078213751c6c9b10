"""Optional physical effects the base model lacks, off by default.

Each effect is a few named parameters whose neutral values leave the base model exactly as it
is; the kernel reads them from its constants (see ``sim.kernels.advance``), so switching an
effect on is a parameter change, never a fork of the kernel. The calibration loop reads
``signature`` to know which variable an effect leaves its trace in.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from sim.checks import InputError, in_range


@dataclass(frozen=True)
class Effect:
    """One optional effect: its parameters with neutral value and bounds, and the trace it leaves."""

    name: str
    parameters: Mapping[str, tuple[float, float, float]]  # name -> (neutral, low, high)
    signature: str  # which variable the residual it leaves follows


EFFECTS: Mapping[str, Effect] = MappingProxyType(
    {
        effect.name: effect
        for effect in (
            Effect(
                "viscous",
                {"coefficient_nms": (0.0, -5e-5, 2e-3)},  # extra viscous coefficient [N·m·s/rad], motor shaft
                "residual torque proportional to motor speed",
            ),
            Effect(
                "stribeck",
                {
                    "amplitude_nm": (0.0, -0.1, 0.2),  # extra dry friction at zero speed [N·m]
                    "speed_radps": (20.0, 0.5, 300.0),  # speed where half of it is left [rad/s]
                },
                "residual torque peaked at low |motor speed|, sign of speed (A / (1 + (ω/ω_s)²))",
            ),
            Effect(
                "torque_constant",
                {"gain": (1.0, 0.7, 1.3)},  # true k_T = k_e over the nominal [-]
                "residual torque proportional to current",
            ),
            Effect(
                "hinge_moment_bias",
                {"bias_nm": (0.0, -100.0, 100.0)},  # offset of the hinge-moment sensor [N·m]
                "constant offset in hinge moment, bias/n in residual torque",
            ),
            Effect(
                "current_sensor_gain",
                {"gain": (1.0, 0.7, 1.3)},  # measured current over true current [-] (the loop sees it)
                "residual torque proportional to current",
            ),
            Effect(
                "position_friction",
                {"amplitude_nm": (0.0, -0.05, 0.1)},  # extra dry friction at full deflection [N·m], ∝ |θ_u|
                "residual torque proportional to |position|, sign of speed",
            ),
            Effect(
                "cogging",
                {
                    "amplitude_nm": (0.0, 0.0, 0.2),  # cogging torque amplitude [N·m]
                    "periods_per_rev": (6.0, 1.0, 48.0),  # ripple periods per motor revolution [-]
                    "phase_rad": (0.0, -4.0, 4.0),  # A·sin(p·θ_m + φ), θ_m from n·θ_u at the window's start
                },
                "residual torque periodic in motor angle",
            ),
            Effect(
                "backlash",
                {"extra_rad": (0.0, -5e-3, 0.02)},  # backlash beyond the nominal BLK [rad], elevator side
                "position error at speed reversals",
            ),
        )
    }
)


@dataclass(frozen=True)
class EffectSet:
    """The effects switched on, with their parameters; empty means the base model."""

    values: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

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
        return EffectSet({**self.values, effect: parameters})

    def as_dict(self) -> dict[str, dict[str, float]]:
        return {name: dict(parameters) for name, parameters in self.values.items()}
