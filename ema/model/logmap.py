"""``ema-logmap/1``: how a rig's or recorder's own columns and units become a window's signals, said once per rig.

A log is read as it was written (``read_mapped``): the time column or the rate, the set point with the
position or its error (the position is then the set point less the error), the current, the load (a
column, or a constant with its sign), each in its unit (mm, m, in, deg, rad, A, mA, N, kgf, lbf, N·m,
rad/s, rpm), converted to ema's. A file that does not match its map is refused naming the column.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from ema.model.checks import InputError, read_document, validated
from ema.model.document import Number

SCHEMA = "ema-logmap/1"
LENGTH_MM = {"mm": 1.0, "m": 1000.0, "in": 25.4}
ANGLE_DEG = {"deg": 1.0, "rad": 180.0 / np.pi}
CURRENT_A = {"A": 1.0, "mA": 1e-3}
FORCE_N = {"N": 1.0, "kgf": 9.80665, "lbf": 4.4482216152605}
TORQUE_NM = {"N·m": 1.0, "Nm": 1.0}
SPEED_RADPS = {"rad/s": 1.0, "rpm": 2.0 * np.pi / 60.0}
TIME_S = {"s": 1.0, "ms": 1e-3}
UNITS = {**LENGTH_MM, **ANGLE_DEG, **CURRENT_A, **FORCE_N, **TORQUE_NM, **SPEED_RADPS, **TIME_S}
UNIFORM = 0.01  # time steps within this share of the median step: uniformly sampled


class _Part(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Column(_Part):
    column: str = Field(min_length=1, description="the column's name in the log's header")
    unit: str = Field(description="its unit: " + ", ".join(UNITS))
    sign: Literal[1, -1] = Field(1, description="-1 where the log counts the other way")


class Constant(_Part):
    value: Number = Field(description="the same in every sample (a load the rig holds)")
    unit: str = Field(description="its unit")


class LogMap(_Part):
    """``ema-logmap/1``."""

    schema_: Literal["ema-logmap/1"] = Field("ema-logmap/1", alias="schema")
    name: str = Field(min_length=1, max_length=200, description="the rig or recorder, for a person")
    kind: Literal["linear", "rotary"] = Field("linear", description="the actuator's kind (its signals)")
    actuator_id: str = Field(min_length=1, max_length=200, description="the actuator every file of this rig logs")
    time: Column | None = Field(None, description="seconds (s or ms) from the start; or give sample_rate_hz")
    sample_rate_hz: Number | None = Field(None, gt=0, description="where the log has no time column")
    set_point: Column = Field(description="the position set point (linear: mm, m, in; rotary: deg, rad)")
    position: Column | None = Field(None, description="the measured position; or give error")
    error: Column | None = Field(None, description="set point minus measured position (sign -1: the other way)")
    current: Column = Field(description="the drive's current (A, mA)")
    load: Column | Constant = Field(
        description="linear: the force (N, kgf, lbf), positive pushing towards increasing position; rotary: the "
        "hinge moment (N·m)"
    )
    motor_speed: Column | None = Field(None, description="rotary: the motor's speed (rad/s, rpm)")

    @model_validator(mode="after")
    def _complete(self) -> LogMap:
        if (self.time is None) == (self.sample_rate_hz is None):
            raise ValueError("time: give the time column or sample_rate_hz, one of them")
        if (self.position is None) == (self.error is None):
            raise ValueError("position: give the position column or the error column, one of them")
        if self.kind == "rotary" and self.motor_speed is None:
            raise ValueError("motor_speed: a rotary actuator's log gives its motor speed")
        wanted = {
            "time": TIME_S,
            "set_point": LENGTH_MM if self.kind == "linear" else ANGLE_DEG,
            "position": LENGTH_MM if self.kind == "linear" else ANGLE_DEG,
            "current": CURRENT_A,
            "load": FORCE_N if self.kind == "linear" else TORQUE_NM,
            "motor_speed": SPEED_RADPS,
        }
        wanted["error"] = wanted["position"]
        for name, units in wanted.items():
            part = getattr(self, name)
            if part is not None and part.unit not in units:
                raise ValueError(f"{name}.unit: {part.unit!r} is not one of {', '.join(units)}")
        return self


def logmap_from_dict(document: Any) -> LogMap:
    return validated(LogMap, document, "log map")


def read_logmap(path: str | Path) -> LogMap:
    return read_document(path, logmap_from_dict)


def _columns(path: Path) -> dict[str, np.ndarray]:
    """The numeric columns of a CSV file (a column with any non-number is kept out: it is text)."""
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(line for line in handle if not line.startswith("#")))
    if not rows:
        raise InputError(str(path), "has no data rows")
    columns = {}
    for name in rows[0]:
        try:
            columns[name] = np.array([float(row[name]) for row in rows])
        except (TypeError, ValueError):
            continue
    return columns


def _read(columns: dict[str, np.ndarray], part: Column | Constant, what: str, path: Path, n: int) -> np.ndarray:
    if isinstance(part, Constant):
        return np.full(n, part.value * UNITS[part.unit])
    if part.column not in columns:
        raise InputError(str(path), f"has no numeric column {part.column!r} (the log map's {what}.column)")
    return columns[part.column] * UNITS[part.unit] * part.sign


def read_mapped(path: str | Path, log_map: LogMap) -> dict[str, Any]:
    """The ``ema-window/1`` document of one logged file, read through ``log_map``; InputError naming the file
    and the column where they do not match."""
    path = Path(path)
    columns = _columns(path)
    n = len(next(iter(columns.values()))) if columns else 0
    read = {
        name: _read(columns, getattr(log_map, name), name, path, n)
        for name in ("set_point", "current", "load") + (("motor_speed",) if log_map.kind == "rotary" else ())
    }
    if log_map.position is not None:
        position = _read(columns, log_map.position, "position", path, n)
    else:
        assert log_map.error is not None
        position = read["set_point"] - _read(columns, log_map.error, "error", path, n)
    rate = log_map.sample_rate_hz or _rate(_read(columns, log_map.time, "time", path, n), path)  # type: ignore[arg-type]
    if log_map.kind == "linear":
        signals = {
            "command_mm": read["set_point"],
            "position_mm": position,
            "current_a": read["current"],
            "load_n": read["load"],
        }
    else:
        signals = {
            "command_deg": read["set_point"],
            "position_deg": position,
            "motor_speed_radps": read["motor_speed"],
            "current_a": read["current"],
            "hinge_moment_nm": read["load"],
        }
    return {
        "schema": "ema-window/1",
        "actuator_id": log_map.actuator_id,
        "window_id": path.stem,
        "sample_rate_hz": float(rate),
        "flight_condition": None,
        "signals": {name: values.tolist() for name, values in signals.items()},
    }


def _rate(time_s: np.ndarray, path: Path) -> float:
    """The sample rate a time column gives, where its steps are uniform (``UNIFORM``)."""
    steps = np.diff(time_s)
    if len(steps) == 0 or np.median(steps) <= 0:
        raise InputError(str(path), "its time column does not increase")
    step = float(np.median(steps))
    if np.max(np.abs(steps - step)) > UNIFORM * step:
        worst = int(np.argmax(np.abs(steps - step)))
        raise InputError(
            str(path),
            f"is not uniformly sampled: its time steps by {steps[worst]:g} s after row "
            f"{worst + 1}, against {step:g} s elsewhere",
        )
    return 1.0 / step
