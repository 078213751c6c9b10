"""The units a log may be written in, each as the factor to ema's own unit of its quantity.

ema computes with the unit in each name (``position_mm``, ``load_n``), and the name is the one place it is said:
a log map names its columns' units, each role of a kind (``ema.model.kinds``) finds the table of its signal's
quantity by the unit its name ends in (``units_of``), and the reader multiplies by the factor.
"""

from __future__ import annotations

import numpy as np

LENGTH_MM = {"mm": 1.0, "m": 1000.0, "in": 25.4, "um": 1e-3}  # to mm
LENGTH_M = {name: factor / 1000.0 for name, factor in LENGTH_MM.items()}  # to m
ANGLE_DEG = {"deg": 1.0, "rad": 180.0 / np.pi}
ANGLE_RAD = {name: factor * np.pi / 180.0 for name, factor in ANGLE_DEG.items()}  # to rad
VOLTAGE_V = {"V": 1.0, "mV": 1e-3}
RATIO = {"1": 1.0, "%": 0.01}  # a share of its full scale (a PWM duty)
FLAG = {"1": 1.0}  # 1 or 0 (a switch: the motor's torque enabled)
CURRENT_A = {"A": 1.0, "mA": 1e-3}
FORCE_N = {"N": 1.0, "kN": 1e3, "kgf": 9.80665, "lbf": 4.4482216152605}
TORQUE_NM = {"N·m": 1.0, "Nm": 1.0}
SPEED_RADPS = {"rad/s": 1.0, "rpm": 2.0 * np.pi / 60.0}
TIME_S = {"s": 1.0, "ms": 1e-3}
UNITS_BY_SUFFIX = {
    "mm": LENGTH_MM,
    "m": LENGTH_M,
    "deg": ANGLE_DEG,
    "rad": ANGLE_RAD,
    "v": VOLTAGE_V,
    "ratio": RATIO,
    "flag": FLAG,
    "a": CURRENT_A,
    "n": FORCE_N,
    "nm": TORQUE_NM,
    "radps": SPEED_RADPS,
    "s": TIME_S,
}


def units_of(name: str) -> dict[str, float]:
    """The units a quantity may be written in, by the unit its ema name ends in (``position_mm``: a length, to mm):
    the name is the one place its unit is said."""
    return UNITS_BY_SUFFIX[name.rsplit("_", 1)[-1]]
