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

A constant asymmetry of the Coulomb level is not among them: while the load moves, it is the offset itself.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ServoEffect:
    name: str
    description: str
    grid: tuple[float, ...]  # its nonlinear constant's candidates (one value: it has none)
    plausible: Callable[[dict[str, float]], bool] = lambda _: True  # of the solved constants
    constant: tuple[str, str] | None = None  # its nonlinear constant's name and unit


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
)
