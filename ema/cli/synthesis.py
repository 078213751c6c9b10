"""``ema simulate``: a synthetic window written as the contract's JSON, with its truth and a summary."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ema.cli.options import actuator_document
from ema.model.actuator import Actuator
from ema.model.aircraft import FlightCondition, GroundLoad
from ema.model.checks import InputError
from ema.model.effects import EffectSet
from ema.model.noise import NO_NOISE
from ema.model.params import HealthParams
from ema.model.residual import residual_torque_nm
from ema.model.synthetic import synthetic_window
from ema.model.window import Window, write_window


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


def summary(window: Window, actuator: Actuator) -> dict[str, Any]:
    """Ranges of the signals and of the reconstructed residual torque, for a human or a script."""
    s = window.signals
    residual = residual_torque_nm(
        s["current_a"], s["motor_speed_radps"], s["hinge_moment_nm"], window.sample_rate_hz, actuator.params
    )
    ranges = {name: [float(values.min()), float(values.max())] for name, values in s.items()}
    ranges["residual_torque_nm"] = [float(residual.min()), float(residual.max())]
    return {
        "actuator_id": window.actuator_id,
        "window_id": window.window_id,
        "n_samples": window.n_samples,
        "duration_s": window.duration_s,
        "sample_rate_hz": window.sample_rate_hz,
        "on_ground": window.on_ground,
        "ranges": ranges,
        "moving_fraction": float(np.mean(np.abs(s["motor_speed_radps"]) > 5.0)),
    }


def synthesize(
    out: Path,
    fdj: float | None,
    eta_o: float | None,
    fsj: float | None,
    airspeed: float,
    altitude: float,
    ground: bool,
    load_nm: float,
    load_ramp_nmps: float,
    command: str,
    seed: int,
    duration: float,
    rate: float,
    clean: bool,
    effect: tuple[str, ...],
    actuator_id: str,
    truth_out: Path | None,
    actuator_file: Path | None,
) -> dict[str, Any]:
    """Simulate the actuator of ``actuator_file`` (the thesis's by default) at the given health (its nominal
    where none is given), write the window (and the truth), return what was written."""
    actuator = actuator_document(actuator_file)
    nominal = actuator.nominal
    health = {
        "FDJ": nominal.fdj_nm if fdj is None else fdj,
        "eta_O": nominal.eta_o if eta_o is None else eta_o,
        "FSJ": nominal.fsj_nm if fsj is None else fsj,
    }
    effects = EffectSet(dict(parse_effect(text) for text in effect))
    load = GroundLoad(load_nm, load_ramp_nmps) if ground else FlightCondition(airspeed, altitude)
    noise = NO_NOISE if clean else actuator.noise
    window = synthetic_window(
        HealthParams.single(fsj_nm=health["FSJ"], fdj_nm=health["FDJ"], eta_o=health["eta_O"]),
        load,
        seed=seed,
        duration_s=duration,
        sample_rate_hz=rate,
        noise=noise,
        effects=effects,
        actuator_id=actuator_id,
        command=command,
        actuator=actuator,
    )
    write_window(window, out)
    if truth_out is not None:
        truth_out.write_text(json.dumps(health, indent=2))
    return {
        "window": str(out),
        "actuator": actuator.name,
        "truth": {**health, "eta_A": float(actuator.eta_a(health["eta_O"]))},
        "command": command,
        "load": "ground" if ground else "flight",
        "effects": effects.as_dict(),
        "noise": "none" if clean else noise.as_dict(),
        "summary": summary(window, actuator),
    }
