"""What a servo's inverse model may lack: each effect's physical reading, the grid of its nonlinear constant, and
when its solved constants are physical. Its columns of Eq. 5.1 are ``ema.kinds.servo.inverse``'s.

- ``viscous_down``: a viscous friction that differs with the direction of motion (a seal, a preload or the
  grease distributed unevenly): C splits into C up and C down.
- ``stribeck``: friction rising at low speed above its sliding level, F_S·exp(−(q̇/v_S)²); physical only with
  F_S > 0.
- ``presliding``: friction that builds up over the first travel after each reversal (the balls' pre-sliding,
  Dahl's model), −F_P·exp(−s/σ)·sgn(q̇), s the travel since the last reversal; physical with 0 < F_P ≤ FDJ.
- ``position_force``: a force that changes along the stroke (a spring, a cable, a slope).
- ``position_friction``: a friction that changes along the stroke (a preload that varies, a local defect).
- ``turn_ripple``: a force that repeats once per turn of the motor, A·sin(2π·q/p) + B·cos(2π·q/p), p the load's
  travel per turn (the document's ``travel_per_turn_m``: without it, not looked for): a screw's, a nut's or a
  coupling's eccentricity or misalignment (a motor's cogging repeats at its poles' count, not once a turn). Its
  phase is fixed to the motor's angle, so it is a force, not a friction.

A constant asymmetry of the Coulomb level is not among them: while the load moves, it is the offset itself.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ema.model.servo import Servo


@dataclass(frozen=True)
class ServoEffect:
    name: str
    description: str
    grid: tuple[float, ...]  # its nonlinear constant's candidates (one value: it has none; none: ``given_by``)
    plausible: Callable[[dict[str, float]], bool] = lambda _: True  # of the solved constants
    constant: tuple[str, str] | None = None  # its nonlinear constant's name and unit
    given_by: str | None = None  # the document's field that gives its one constant (the grid), not learned

    def candidates(self, servo: Servo) -> tuple[float, ...]:
        """Its nonlinear constant's candidates for ``servo``: the grid, or the document's value where it gives it
        (none: the effect is not looked for)."""
        if self.given_by is None:
            return self.grid
        value = getattr(servo, self.given_by)
        return () if value is None else (float(value),)


LOAD_EFFECTS = (
    ServoEffect(
        "viscous_down",
        "a viscous friction that differs with the direction of motion",
        (1.0,),
        lambda c: c["viscous_up_ns_per_m"] >= 0 and c["viscous_down_ns_per_m"] >= 0,
    ),
    ServoEffect(
        "stribeck",
        "friction rising at low speed above its sliding level (Stribeck)",
        tuple(np.geomspace(0.002, 0.05, 9)),
        lambda c: c["stribeck_n"] > 0,
        ("stribeck_speed_mps", "m/s"),
    ),
    ServoEffect(
        "presliding",
        "friction building up over the first travel after each reversal (pre-sliding, Dahl)",
        tuple(np.geomspace(2e-5, 5e-3, 9)),
        lambda c: 0 < c["presliding_n"] <= c["fdj_n"],
        ("presliding_travel_m", "m"),
    ),
    ServoEffect("position_force", "a force that changes along the stroke (a spring, a cable, a slope)", (1.0,)),
    ServoEffect("position_friction", "a friction that changes along the stroke (a varying preload, a defect)", (1.0,)),
    ServoEffect(
        "turn_ripple",
        "a force repeating once per turn of the motor (a screw's, a nut's or a coupling's eccentricity)",
        (),
        given_by="travel_per_turn_m",
    ),
)


def looked_for(servo: Servo, model: Mapping[str, float]) -> tuple[ServoEffect, ...]:
    """The effects a servo's logs may be read with on top of ``model``: not in it, and with a candidate constant."""
    return tuple(e for e in LOAD_EFFECTS if e.name not in model and e.candidates(servo))
