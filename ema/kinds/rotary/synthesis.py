"""``ema simulate`` for the rotary kind: synthetic windows of its simulator written as the contract's JSON, with their
truth and a summary."""

from __future__ import annotations

import datetime as dt
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ema.kinds.rotary.simulator.effects import EFFECTS, EffectSet
from ema.kinds.rotary.simulator.loads import GroundLoad
from ema.kinds.rotary.simulator.residual import residual_torque_nm
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import RotaryActuator
from ema.model.aircraft import FlightCondition
from ema.model.checks import InputError
from ema.model.noise import NO_NOISE, SensorNoise
from ema.model.params import HealthParams
from ema.model.window import RotaryWindow, write_window


def parse_effect(text: str) -> tuple[str, dict[str, float]]:
    """``name:key=value,key=value`` (or just ``name`` for its neutral values) -> (name, parameters)."""
    name, _, assignments = text.partition(":")
    name = name.strip()
    if name not in EFFECTS:
        raise InputError("--effect", f"unknown effect {name!r}; known: {', '.join(EFFECTS)}")
    parameters: dict[str, float] = {}
    for assignment in filter(None, assignments.split(",")):
        key, sep, value = assignment.partition("=")
        if not sep:
            raise InputError("--effect", f"expected key=value in {assignment!r}")
        try:
            parameters[key.strip()] = float(value)
        except ValueError:
            raise InputError(f"--effect {name}.{key}", f"{value!r} is not a number") from None
    return name, parameters


def summary(window: RotaryWindow, actuator: RotaryActuator) -> dict[str, Any]:
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


def _healths(
    actuator: RotaryActuator,
    *,
    start: tuple[float | None, float | None, float | None],
    end: tuple[float | None, float | None],
    series: int,
) -> list[dict[str, float]]:
    """Each window's FDJ, η_O and FSJ: ``start`` (FDJ, η_O, FSJ; the nominal where None) moving linearly to
    ``end`` (FDJ, η_O; no change where None) over ``series`` windows, FSJ never below FDJ (static friction
    never below dynamic)."""
    nominal_health = actuator.nominal
    if nominal_health is None or nominal_health.fsj is None:
        raise InputError("--actuator", "gives no nominal FDJ, FSJ and η_O to draw its windows at")
    nominal = (nominal_health.fdj, nominal_health.efficiency, nominal_health.fsj)
    first = {
        name: default if given is None else given
        for name, given, default in zip(("FDJ", "eta_O", "FSJ"), start, nominal, strict=True)
    }
    last = {name: first[name] if given is None else given for name, given in zip(("FDJ", "eta_O"), end, strict=True)}
    healths: list[dict[str, float]] = []
    for i in range(series):
        share = i / max(series - 1, 1)
        now = {name: first[name] + share * (last[name] - first[name]) for name in last}
        healths.append(now | {"FSJ": max(first["FSJ"], now["FDJ"])})
    return healths


@dataclass(frozen=True)
class Draw:
    """What ``ema simulate`` was asked for, one field per flag (``--fdj`` is ``fdj``, and so on)."""

    out: Path
    fdj: float | None
    eta_o: float | None
    fsj: float | None
    airspeed: float
    altitude: float
    ground: bool
    load_nm: float
    load_ramp_nmps: float
    command: str
    seed: int
    duration: float
    rate: float
    clean: bool
    effect: tuple[str, ...]
    actuator_id: str
    truth_out: Path | None
    recorded_at: dt.datetime | None = None
    flight_hours: float | None = None
    series: int = 1
    every_hours: float = 10.0
    fdj_end: float | None = None
    eta_o_end: float | None = None


def _window(
    draw: Draw,
    actuator: RotaryActuator,
    health: dict[str, float],
    index: int,
    *,
    noise: SensorNoise,
    effects: EffectSet,
) -> RotaryWindow:
    """The ``index``-th window of ``draw`` at ``health`` (FDJ, η_O, FSJ), stamped ``index`` steps of
    ``every_hours`` on from ``flight_hours`` and ``recorded_at`` where a series or a time was asked for."""
    window = synthetic_window(
        HealthParams.single(fsj_nm=health["FSJ"], fdj_nm=health["FDJ"], eta_o=health["eta_O"]),
        condition=GroundLoad(draw.load_nm, draw.load_ramp_nmps)
        if draw.ground
        else FlightCondition(draw.airspeed, draw.altitude),
        seed=draw.seed + index,
        duration_s=draw.duration,
        sample_rate_hz=draw.rate,
        noise=noise,
        effects=effects,
        actuator_id=draw.actuator_id,
        command=draw.command,
        actuator=actuator,
    )
    offset = index * draw.every_hours
    hours = None if draw.flight_hours is None and draw.series == 1 else (draw.flight_hours or 0.0) + offset
    stamp = None if draw.recorded_at is None else (draw.recorded_at + dt.timedelta(hours=offset)).isoformat()
    window_id = f"series-{draw.seed}-{index:03d}" if draw.series > 1 else window.window_id
    return replace(window, window_id=window_id, flight_hours=hours, recorded_at=stamp)


def synthesize(draw: Draw, actuator: RotaryActuator) -> dict[str, Any]:
    """Simulate ``actuator`` at the given health (its nominal
    where none is given), write the window (and the truth), return what was written. With ``series`` > 1,
    ``out`` is a folder of that many windows of a degrading actuator, its health moving linearly to
    ``fdj_end`` and ``eta_o_end``, ``every_hours`` flight hours apart (and as many hours apart in recorded_at)."""
    noise = NO_NOISE if draw.clean else actuator.noise
    effects = EffectSet(dict(parse_effect(text) for text in draw.effect))  # a malformed flag named before any write
    start, end = (draw.fdj, draw.eta_o, draw.fsj), (draw.fdj_end, draw.eta_o_end)
    healths = _healths(actuator, start=start, end=end, series=draw.series)
    if draw.series > 1:
        draw.out.mkdir(parents=True, exist_ok=True)
    written, truths = [], []
    for i, health in enumerate(healths):
        window = _window(draw, actuator, health, i, noise=noise, effects=effects)
        path = draw.out / f"{window.window_id}.json" if draw.series > 1 else draw.out
        write_window(window, path)
        written.append(str(path))
        truths.append({**health, "eta_A": float(actuator.eta_a(health["eta_O"])), "flight_hours": window.flight_hours})
    if draw.truth_out is not None:
        draw.truth_out.write_text(json.dumps(truths[0] if draw.series == 1 else truths, indent=2))
    return {
        "window": written[0] if draw.series == 1 else str(draw.out),
        "windows": written,
        "actuator": actuator.name,
        "truth": truths[0] if draw.series == 1 else truths,
        "command": draw.command,
        "load": "ground" if draw.ground else "flight",
        "effects": effects.as_dict(),
        "noise": "none" if draw.clean else noise.as_dict(),
        "summary": summary(window, actuator),
    }
