"""Residual channels between a measured window and its simulation, and the variables they may follow.

Both sides go through the same reconstruction and smoothing (``sim.residual``), so what is left
is model error plus noise. Three channels carry the candidate effects' signatures:

- ``torque``: ΔT_R, the residual torque mismatch [N·m];
- ``kinematic``: Δd, the mismatch of d = θ_m/n − θ_u, the motor angle (integrated measured speed)
  minus the elevator angle: the dead band shows up there as a square wave of height BLK;
- ``hinge``: ΔH, the hinge-moment mismatch [N·m].
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from sim.params import ActuatorParams
from sim.residual import DEFAULT_DERIVATIVE_WINDOW_S, residual_torque_nm, smoothed

CHANNELS = ("torque", "kinematic", "hinge")
END_STOP_MARGIN_DEG = 1.0
SETTLE_S = 0.02  # the first 20 ms: the simulation is still settling from an estimated first state
MIN_SPEED_RADPS = 30.0  # and away from reversals, where a 0.1 ms timing difference is a torque spike


@dataclass(frozen=True)
class Residuals:
    channels: dict[str, np.ndarray]  # name -> (n,) residual, measured − simulated
    variables: dict[str, np.ndarray]  # name -> (n,) what a signature may follow (from the measured window)
    mask: np.ndarray  # (n,) samples to use: settled, away from reversals, the window's end and the end stops
    rms_report: dict[str, float]  # RMS of the reported residuals (interfaces.md names)


def motor_angle_rad(speed_radps: np.ndarray, position_deg: np.ndarray, rate_hz: float, gear: float) -> np.ndarray:
    """θ_m at each interval centre: n·θ_u(0) plus the integral of the interval-mean speed."""
    step = 1.0 / rate_hz
    return gear * np.radians(position_deg[0]) + step * (np.cumsum(speed_radps) - 0.5 * speed_radps)


def held_direction(speed: np.ndarray, threshold: float) -> np.ndarray:
    """Sign of the last motion above ``threshold``: which side of the dead band the motor pushes on."""
    sign = np.where(np.abs(speed) > threshold, np.sign(speed), 0.0)
    index = np.where(sign != 0, np.arange(len(sign)), 0)
    np.maximum.accumulate(index, out=index)
    held = sign[index]
    first = np.flatnonzero(sign)
    if len(first):
        held[: first[0]] = sign[first[0]]
    return held


def _dead_band(signals: Mapping[str, np.ndarray], rate: float, actuator: ActuatorParams) -> np.ndarray:
    theta_m = motor_angle_rad(signals["motor_speed_radps"], signals["position_deg"], rate, actuator.gear_ratio)
    return theta_m / actuator.gear_ratio - np.radians(signals["position_deg"])


def residuals(
    measured: Mapping[str, np.ndarray],
    simulated: Mapping[str, np.ndarray],
    rate: float,
    actuator: ActuatorParams = ActuatorParams(),
    window_s: float = DEFAULT_DERIVATIVE_WINDOW_S,
) -> Residuals:
    """The residual channels and the measured variables, with one filtering on both sides."""

    def torque(s: Mapping[str, np.ndarray]) -> np.ndarray:
        return residual_torque_nm(
            s["current_a"], s["motor_speed_radps"], s["hinge_moment_nm"], rate, actuator, window_s
        )

    def smooth(values: np.ndarray) -> np.ndarray:
        return smoothed(values, rate, window_s)

    speed = smooth(measured["motor_speed_radps"])
    position_rad = np.radians(smooth(measured["position_deg"]))
    load = smooth(measured["hinge_moment_nm"]) / actuator.gear_ratio
    channels = {
        "torque": torque(measured) - torque(simulated),
        "kinematic": smooth(_dead_band(measured, rate, actuator) - _dead_band(simulated, rate, actuator)),
        "hinge": smooth(measured["hinge_moment_nm"] - simulated["hinge_moment_nm"]),
    }
    variables = {
        "speed_radps": speed,
        "position_rad": position_rad,
        "load_nm": load,
        "current_a": smooth(measured["current_a"]),
        "motor_angle_rad": motor_angle_rad(
            measured["motor_speed_radps"], measured["position_deg"], rate, actuator.gear_ratio
        ),
        "direction": held_direction(speed, threshold=5.0),
        "time_s": np.arange(len(speed)) / rate,
    }
    edge = 2 * round(window_s * rate)
    mask = np.ones(len(speed), dtype=bool)
    mask[: max(edge, round(SETTLE_S * rate))] = False
    mask[-edge:] = False
    mask &= np.abs(measured["position_deg"]) < actuator.end_stop_deg - END_STOP_MARGIN_DEG
    padded = np.pad(np.abs(speed), edge, mode="edge")
    slowest_near = np.lib.stride_tricks.sliding_window_view(padded, 2 * edge + 1).min(axis=1)
    mask &= slowest_near > MIN_SPEED_RADPS
    rms = {
        "residual_torque": channels["torque"][mask],
        "motor_speed": smooth(measured["motor_speed_radps"] - simulated["motor_speed_radps"])[mask],
        "position": (measured["position_deg"] - simulated["position_deg"])[mask],
        "current": (measured["current_a"] - simulated["current_a"])[mask],
        "hinge_moment": channels["hinge"][mask],
    }
    return Residuals(channels, variables, mask, {k: float(np.sqrt(np.mean(v**2))) for k, v in rms.items()})
