"""What a geared servo's model is made of for its calibration: the constants every model solves, and the effects
``ema calibrate`` may adopt beyond a constant friction, each with the constants it frees.

- ``efficiency``: a friction that grows with the load the gear train carries, by whether the load opposes the
  motion or aids it: the thesis's η_O and η_A (Borello's model);
- ``command_delay``: the set point reaches the loop late (a bus's and a firmware's transport), a delay in s;
- ``min_duty``: the firmware adds a minimum duty the way the error points (a dead band's compensation);
- ``static_friction``: a shaft at rest is held by more than the sliding friction (FSD above 1).

A model is a set of free constants over ``CONSTANTS``; the others stay at their neutral values (no effect).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

CONSTANTS = ("torque_per_volt", "back_emf", "inertia_kg_m2", "error_gain_per_rad", "duty_limit", "min_duty",
             "fdj_nm", "viscous_nm_s_per_rad", "k_opp", "k_aid", "static_friction_ratio",
             "command_delay_s")  # fmt: skip
BASE = ("torque_per_volt", "back_emf", "inertia_kg_m2", "error_gain_per_rad", "duty_limit", "fdj_nm",
        "viscous_nm_s_per_rad")  # fmt: skip  # a constant friction's model: what every model solves
NEUTRAL = MappingProxyType(
    {"min_duty": 0.0, "k_opp": 0.0, "k_aid": 0.0, "static_friction_ratio": 1.0, "command_delay_s": 0.0}
)
LOW = MappingProxyType({"torque_per_volt": 1e-3, "back_emf": 0.0, "inertia_kg_m2": 1e-6, "error_gain_per_rad": 1e-3,
                        "duty_limit": 0.2, "min_duty": 0.0, "fdj_nm": 0.0, "viscous_nm_s_per_rad": 0.0, "k_opp": 0.0,
                        "k_aid": 0.0, "static_friction_ratio": 1.0, "command_delay_s": 0.0})  # fmt: skip
HIGH = MappingProxyType({"torque_per_volt": 1e3, "back_emf": 1e3, "inertia_kg_m2": 1e3, "error_gain_per_rad": 1e3,
                         "duty_limit": 1.0, "min_duty": 0.3, "fdj_nm": 1e3, "viscous_nm_s_per_rad": 1e3, "k_opp": 9.0,
                         "k_aid": 2.0, "static_friction_ratio": 10.0, "command_delay_s": 0.2})  # fmt: skip


@dataclass(frozen=True)
class Effect:
    name: str
    frees: tuple[str, ...]  # the constants it adds to a model
    start: Mapping[str, float]  # where a solve starts them (off their neutral value: a flat start stays flat)
    follows: str  # what its trace follows, for a person
    says: str  # the effect, for a person


EFFECTS: Mapping[str, Effect] = MappingProxyType(
    {
        effect.name: effect
        for effect in (
            Effect(
                "efficiency",
                ("k_opp", "k_aid"),
                {"k_opp": 0.1, "k_aid": 0.1},
                "the load carried, by whether it opposes or aids the motion",
                "a friction that grows with the load the gear train carries, split by whether the load opposes the "
                "motion (η_O) or aids it (η_A): the thesis's efficiencies",
            ),
            Effect(
                "command_delay",
                ("command_delay_s",),
                {"command_delay_s": 0.01},
                "time",
                "the set point reaches the loop late (the bus's and the firmware's transport)",
            ),
            Effect(
                "min_duty",
                ("min_duty",),
                {"min_duty": 0.01},
                "the position error's sign",
                "the firmware adds a minimum duty the way the error points (its dead band's compensation)",
            ),
            Effect(
                "static_friction",
                ("static_friction_ratio",),
                {"static_friction_ratio": 1.2},
                "rest",
                "a shaft at rest is held by more than the sliding friction (static over dynamic, FSD)",
            ),
        )
    }
)
DIFF_STEPS = MappingProxyType({"static_friction_ratio": 0.05, "command_delay_s": 0.05, "min_duty": 0.02})
# a solve's relative finite-difference step where the default's (``output_error.DIFF_STEP``) changes too few samples
# of a run to show a slope: a hold that a 0.1 % larger FSD keeps, a delay that a 0.1 % change moves by 40 µs
EFFICIENCY = "efficiency"  # the thesis's own effect: tested first, the others then on what it leaves


def free_constants(effects: Iterable[str]) -> tuple[str, ...]:
    """The constants a model with ``effects`` solves, in ``CONSTANTS`` order."""
    free = set(BASE).union(*(EFFECTS[name].frees for name in effects))
    return tuple(name for name in CONSTANTS if name in free)


def diff_steps(free: tuple[str, ...], default: float) -> np.ndarray:
    return np.array([DIFF_STEPS.get(name, default) for name in free])


def bounds(free: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    return np.array([LOW[name] for name in free]), np.array([HIGH[name] for name in free])
