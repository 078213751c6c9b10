"""The candidate effects: the columns each adds to the residual model, and its parameters from the fit.

Every candidate is linear in its coefficients once its grid parameter (if any) is fixed: the
Stribeck speed ω_s, the cogging order p. The nuisance columns, always present, let FDJ and the
load-dependent friction move too: a missing effect biases the base estimates, and the residual
must be judged after they have absorbed what they can (e.g. extra viscous friction at a speed
held near ω_max looks like extra FDJ).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from sim.effects import EFFECTS
from sim.params import ActuatorParams

Columns = dict[str, np.ndarray]  # channel -> (n, k) design columns


@dataclass(frozen=True)
class Candidate:
    effect: str
    grid: tuple[float, ...]  # values of the one nonlinear parameter, or (nan,) if none
    columns: Callable[[Mapping[str, np.ndarray], float, ActuatorParams], Columns]
    parameters: Callable[[dict[str, np.ndarray], float], dict[str, float]]


def _sign(v: Mapping[str, np.ndarray]) -> np.ndarray:
    return np.sign(v["speed_radps"])


def nuisance(v: Mapping[str, np.ndarray], actuator: ActuatorParams) -> Columns:
    """FDJ and the aiding / opposing load parts may shift; the dead band's centre is unknown."""
    sign = _sign(v)
    load = np.abs(v["load_nm"])
    aiding = v["load_nm"] * sign > 0
    torque = np.stack([sign, sign * load * aiding, sign * load * ~aiding], axis=1)
    return {"torque": torque, "kinematic": np.ones((len(sign), 1)), "hinge": np.zeros((len(sign), 0))}


def _one(channel: str, column: np.ndarray) -> Columns:
    return {channel: column[:, None]}


NO_GRID = (float("nan"),)
STRIBECK_SPEEDS = (2.0, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0)
COGGING_ORDERS = tuple(float(p) for p in range(1, 49))

CANDIDATES: tuple[Candidate, ...] = (
    Candidate(
        "viscous",
        NO_GRID,
        lambda v, g, a: _one("torque", v["speed_radps"]),
        lambda c, g: {"coefficient_nms": float(c["torque"][0])},
    ),
    Candidate(
        "stribeck",
        STRIBECK_SPEEDS,
        lambda v, g, a: _one("torque", _sign(v) / (1.0 + (v["speed_radps"] / g) ** 2)),
        lambda c, g: {"amplitude_nm": float(c["torque"][0]), "speed_radps": g},
    ),
    Candidate(
        "torque_constant",
        NO_GRID,
        lambda v, g, a: _one("torque", a.torque_constant_nm_per_a * v["current_a"]),
        lambda c, g: {"gain": 1.0 - float(c["torque"][0])},
    ),
    Candidate(
        "current_sensor_gain",
        NO_GRID,
        lambda v, g, a: _one("torque", a.torque_constant_nm_per_a * v["current_a"]),
        lambda c, g: {"gain": 1.0 / (1.0 - float(c["torque"][0]))},
    ),
    Candidate(
        "hinge_moment_bias",
        NO_GRID,
        lambda v, g, a: {
            "torque": np.full((len(v["speed_radps"]), 1), 1.0 / a.gear_ratio),
            "hinge": np.ones((len(v["speed_radps"]), 1)),
        },
        lambda c, g: {"bias_nm": float(c["hinge"][0])},
    ),
    Candidate(
        "position_friction",
        NO_GRID,
        lambda v, g, a: _one("torque", _sign(v) * np.abs(v["position_rad"]) / np.radians(a.end_stop_deg)),
        lambda c, g: {"amplitude_nm": float(c["torque"][0])},
    ),
    Candidate(
        "cogging",
        COGGING_ORDERS,
        lambda v, g, a: {
            "torque": np.stack([np.sin(g * v["motor_angle_rad"]), np.cos(g * v["motor_angle_rad"])], axis=1)
        },
        lambda c, g: {
            "amplitude_nm": float(np.hypot(*c["torque"][:2])),
            "periods_per_rev": g,
            "phase_rad": float(np.arctan2(c["torque"][1], c["torque"][0])),
        },
    ),
    Candidate(
        "backlash",
        NO_GRID,
        lambda v, g, a: _one("kinematic", v["direction"] / 2.0),
        lambda c, g: {"extra_rad": float(c["kinematic"][0])},
    ),
)
BY_NAME = {candidate.effect: candidate for candidate in CANDIDATES}

# The channel each effect mostly shows in (the rest: the residual torque).
PRIMARY = {"backlash": "kinematic", "hinge_moment_bias": "hinge"}

# What each signature follows: where its residual shows, for reports and figures.
FOLLOWS = {
    "viscous": "speed_radps",
    "stribeck": "speed_radps",
    "torque_constant": "current_a",
    "current_sensor_gain": "current_a",
    "hinge_moment_bias": "time_s",
    "position_friction": "position_rad",
    "cogging": "motor_angle_rad",
    "backlash": "direction",
}


def refined(effect: str, current: Mapping[str, float], increment: Mapping[str, float]) -> dict[str, float]:
    """Parameters after a refinement round: ``increment`` was fitted to the residual the model with
    ``current`` still leaves, so it is a correction on top of them (in each effect's own algebra)."""
    if effect == "torque_constant":  # residual coefficient c = g_model − g_true, and increment = 1 − c
        return {"gain": current["gain"] - (1.0 - increment["gain"])}
    if effect == "current_sensor_gain":  # residual coefficient is a change of 1 − 1/s
        return {"gain": 1.0 / (1.0 / current["gain"] - 1.0 + 1.0 / increment["gain"])}
    if effect == "cogging":  # amplitude and phase combine as phasors
        z = current["amplitude_nm"] * np.exp(1j * current["phase_rad"])
        z += increment["amplitude_nm"] * np.exp(1j * increment["phase_rad"])
        return {
            "amplitude_nm": float(abs(z)),
            "periods_per_rev": current["periods_per_rev"],
            "phase_rad": float(np.angle(z)),
        }
    additive = {"coefficient_nms", "amplitude_nm", "bias_nm", "extra_rad"}
    return {k: current[k] + increment[k] if k in additive else current[k] for k in current}


def within_bounds(effect: str, parameters: Mapping[str, float]) -> bool:
    """Whether fitted parameters are ones the effect (and the simulator) admits."""
    spec = EFFECTS[effect].parameters
    return all(spec[key][1] <= value <= spec[key][2] for key, value in parameters.items())
