"""``ema simulate``: a synthetic window written as the contract's JSON, with its truth and a summary."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from sim.aircraft import FlightCondition
from sim.checks import InputError
from sim.effects import EffectSet
from sim.noise import NO_NOISE, SensorNoise
from sim.params import HealthParams, eta_a_from_eta_o
from sim.residual import residual_torque_nm
from sim.synthetic import synthetic_window
from sim.window import Window, write_window


def parse_effect(text: str) -> tuple[str, dict[str, float]]:
    """``name:key=value,key=value`` (or just ``name`` for its neutral values) -> (name, parameters)."""
    name, _, assignments = text.partition(":")
    parameters: dict[str, float] = {}
    for assignment in filter(None, assignments.split(",")):
        key, sep, value = assignment.partition("=")
        if not sep:
            raise InputError("--effect", f"expected key=value in {assignment!r}")
        try:
            parameters[key.strip()] = float(value)
        except ValueError:
            raise InputError(f"--effect {name}.{key}", f"{value!r} is not a number") from None
    return name.strip(), parameters


def summary(window: Window) -> dict[str, Any]:
    """Ranges of the signals and of the reconstructed residual torque, for a human or a script."""
    s = window.signals
    residual = residual_torque_nm(s["current_a"], s["motor_speed_radps"], s["hinge_moment_nm"], window.sample_rate_hz)
    ranges = {name: [float(values.min()), float(values.max())] for name, values in s.items()}
    ranges["residual_torque_nm"] = [float(residual.min()), float(residual.max())]
    return {
        "actuator_id": window.actuator_id,
        "window_id": window.window_id,
        "n_samples": window.n_samples,
        "duration_s": window.duration_s,
        "sample_rate_hz": window.sample_rate_hz,
        "ranges": ranges,
        "moving_fraction": float(np.mean(np.abs(s["motor_speed_radps"]) > 5.0)),
    }


def synthesize(
    out: Path, fdj: float, eta_o: float, fsj: float, airspeed: float, altitude: float, command: str, seed: int,
    duration: float, rate: float, clean: bool, effect: tuple[str, ...], actuator_id: str, truth_out: Path | None,
) -> dict[str, Any]:  # fmt: skip
    """Simulate, write the window (and the truth), return what was written."""
    effects = EffectSet(dict(parse_effect(text) for text in effect))
    window = synthetic_window(
        HealthParams.single(fsj_nm=fsj, fdj_nm=fdj, eta_o=eta_o), FlightCondition(airspeed, altitude), seed=seed,
        duration_s=duration, sample_rate_hz=rate, noise=NO_NOISE if clean else SensorNoise(), effects=effects,
        actuator_id=actuator_id, command=command,
    )  # fmt: skip
    write_window(window, out)
    truth = {"FDJ": fdj, "eta_O": eta_o, "FSJ": fsj}
    if truth_out is not None:
        truth_out.write_text(json.dumps(truth, indent=2))
    return {
        "window": str(out),
        "truth": {**truth, "eta_A": float(eta_a_from_eta_o(eta_o))},
        "command": command,
        "effects": effects.as_dict(),
        "noise": "none" if clean else SensorNoise().as_dict(),
        "summary": summary(window),
    }
