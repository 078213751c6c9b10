"""``ema-logmap/1``: how a rig's or recorder's own variables and units become a window's signals, said once per rig.

A log is read as it was written (``read_mapped``): a CSV, a MATLAB file or a NumPy archive
(``ema.model.log_files``). The map names, for each role of its kind (``ema.model.kinds``: the set point, the
position or its error, the current, the force, the load, the motor speed), the file's variable and its unit,
optionally a scale (a number, or a constant stored in the file: a drive's newtons per volt) and a sign; the
time variable or the rate; and the constants the file records for the actuator's document (a controller's
gains). A load may be a constant, or absent where the kind allows it: a window without an external load is
one without a load, not a stuck sensor. A file that does not match its map is refused naming the variable.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, Tag, TypeAdapter, model_validator

from ema.model.bounds import IDENTIFIER
from ema.model.checks import InputError, kind_named, read_document, tagged_by, validated
from ema.model.document import Number
from ema.model.kinds import KIND_NAMES, KINDS, Role
from ema.model.log_files import Table, read_table
from ema.model.units import FLAG, TIME_S, units_of

LOGMAP_SCHEMA = "ema-logmap/1"
SIGN_BIT_TOLERANCE = 1e-6  # a sign bit read from a float32 column: within this share of it is it
UNIFORM = 0.01  # time steps within this share of the median step: uniformly sampled
ROLES = ("set_point", "position", "error", "current", "force", "load", "motor_speed", "duty", "supply", "motor_on")
DEFAULT_LOG_KIND = "linear"  # a map that names no kind: a rig's, as the first log maps were
_KIND_DESCRIPTION = "the actuator's kind (its signals)"


class _Part(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Column(_Part):
    column: str = Field(min_length=1, description="the variable's name: a CSV column, a MATLAB or NumPy variable")
    unit: str = Field(description="its unit once scaled (the kind's role says which it may be)")
    sign: Literal[1, -1] = Field(1, description="-1 where the log counts the other way")
    scale: Number | str | None = Field(
        None,
        description="a factor the variable is multiplied by into its unit (a drive's newtons per volt), or the name "
        "of a constant stored in the file that holds it",
    )
    raw_unit: str | None = Field(None, description="the variable's own unit before the scale, for a person")
    sign_bit: Number | None = Field(
        None,
        gt=0,
        description="where the log writes a sign and a magnitude (a servo's register): a value at or above it is it "
        "plus a magnitude of one sign (sign: 1, positive), one below it a magnitude of the other; null: signed",
    )


class Constant(_Part):
    value: Number = Field(description="the same in every sample (a load the rig holds)")
    unit: str = Field(description="its unit")


class LogMap(_Part):
    """``ema-logmap/1``: what every kind's log map holds. A map is one kind's class (``RotaryLogMap``,
    ``LinearLogMap``, ``ServoLogMap``), which adds the roles only its kind logs; ``AnyLogMap`` joins them on
    ``kind`` (a map without one is a linear rig's, as first published)."""

    schema_: Literal["ema-logmap/1"] = Field("ema-logmap/1", alias="schema")
    name: str = Field(min_length=1, max_length=200, description="the rig or recorder, for a person")
    kind: str  # each kind's class narrows it to its name
    actuator_id: str = Field(min_length=1, max_length=200, description="the actuator every file of this rig logs")
    time: Column | None = Field(None, description="seconds (s or ms) from the start; or give sample_rate_hz")
    sample_rate_hz: Number | None = Field(None, gt=0, description="where the log has no time variable")
    resample_hz: Number | None = Field(
        None,
        gt=0,
        le=100_000,
        description="a log whose time steps are uneven (a recorder's own time stamps) is resampled to this rate, "
        "linearly (a switch: to its nearest sample); null: uneven steps are refused",
    )
    set_point: Column = Field(description="the position set point (linear: mm, m, in; rotary: deg, rad; servo: m)")
    position: Column | None = Field(None, description="the measured position; or give error")
    error: Column | None = Field(None, description="set point minus measured position (sign -1: the other way)")
    constants: dict[str, str] = Field(
        default_factory=dict,
        description="the actuator document's section field -> the file's constant that holds it (a servo's "
        "position_gain_per_s: kp)",
    )

    @model_validator(mode="before")
    @classmethod
    def _its_own_roles(cls, values: Any) -> Any:
        """Another kind's role refused naming it, one of its own missing named (a null role is absent). The shared
        class alone holds no map."""
        kind = kind_named(values, DEFAULT_LOG_KIND, KINDS, shared=cls if cls is LogMap else None)
        if kind is None:
            return values
        roles = KINDS[kind].roles
        values = {name: v for name, v in values.items() if v is not None or name not in ROLES}
        for name in ROLES:
            role = roles.get("position" if name == "error" else name)
            if role is None and name in values:
                raise ValueError(f"{name}: a {kind} actuator's log has no {name} ({', '.join(roles)})")
            if role is not None and role.required and name not in ("position", "error") and name not in values:
                raise ValueError(f"{name}: a {kind} actuator's log gives its {name}")
        return values

    @model_validator(mode="after")
    def _complete(self) -> LogMap:
        if (self.time is None) == (self.sample_rate_hz is None):
            raise ValueError("time: give the time variable or sample_rate_hz, one of them")
        if (self.position is None) == (self.error is None):
            raise ValueError("position: give the position variable or the error variable, one of them")
        for name in ROLES:
            role, part = self.roles.get("position" if name == "error" else name), self.part(name)
            if role is not None and part is not None and part.unit not in role.units:
                raise ValueError(f"{name}.unit: {part.unit!r} is not one of {', '.join(role.units)}")
        for name in self.constants:
            if (why := KINDS[self.kind].recorded_field(name)) is not None:
                raise ValueError(f"constants.{name}: {why}")
        if self.time is not None and self.time.unit not in TIME_S:
            raise ValueError(f"time.unit: {self.time.unit!r} is not one of {', '.join(TIME_S)}")
        return self

    @property
    def roles(self) -> Mapping[str, Role]:
        """The roles its kind's log holds (``ema.model.kinds``)."""
        return KINDS[self.kind].roles

    def part(self, name: str) -> Column | Constant | None:
        """Where the log holds role ``name`` (None: a role this map leaves out)."""
        return getattr(self, name, None)


class RotaryLogMap(LogMap):
    """A rotary actuator's log: its current, its motor's speed and the hinge moment besides."""

    kind: Literal["rotary"] = Field(description=_KIND_DESCRIPTION)
    current: Column = Field(description="the drive's current (A, mA)")
    motor_speed: Column = Field(description="the motor's speed (rad/s, rpm)")
    load: Column | Constant = Field(description="the hinge moment (N·m)")


class LinearLogMap(LogMap):
    """A linear actuator's log: its drive's current and the load besides."""

    kind: Literal["linear"] = Field("linear", description=_KIND_DESCRIPTION)
    current: Column = Field(description="the drive's current (A, mA)")
    load: Column | Constant = Field(
        description="the external force (N, kgf, lbf), positive pushing towards increasing position"
    )


class ServoLogMap(LogMap):
    """A servo's log: its drive's force on the load, and the load where it has one."""

    kind: Literal["servo"] = Field(description=_KIND_DESCRIPTION)
    force: Column = Field(description="the drive's force on the load (N; a command with a scale)")
    load: Column | Constant | None = Field(
        None,
        description="the external force (N, kgf, lbf), positive pushing towards increasing position; left out: no load",
    )


class GearedLogMap(LogMap):
    """A geared servo's log: the duty its loop applied, the supply, and where it records it, its motor switched on."""

    kind: Literal["geared"] = Field(description=_KIND_DESCRIPTION)
    duty: Column = Field(description="the PWM duty its loop applied (1: the whole supply, or %)")
    supply: Column | Constant = Field(description="the supply voltage (V)")
    motor_on: Column | None = Field(None, description="1 where the motor's torque is on (a log's true/false)")


AnyLogMap = Annotated[
    Annotated[RotaryLogMap, Tag("rotary")]
    | Annotated[LinearLogMap, Tag("linear")]
    | Annotated[ServoLogMap, Tag("servo")]
    | Annotated[GearedLogMap, Tag("geared")],
    tagged_by("kind", KIND_NAMES, DEFAULT_LOG_KIND),
]
LOG_MAP: TypeAdapter[LogMap] = TypeAdapter(AnyLogMap)  # what parses and exports it


def logmap_schema() -> dict[str, Any]:
    """The JSON Schema of ``ema-logmap/1``: one kind's map, chosen by ``kind``."""
    return {"title": "LogMap", **LOG_MAP.json_schema(by_alias=True)}


def logmap_from_dict(document: Any) -> LogMap:
    """Parse and validate an ``ema-logmap/1`` document (a dict) as its kind's class; errors name the field."""
    return validated(LOG_MAP, document, "log map", tags=KIND_NAMES)


def read_logmap(path: str | Path) -> LogMap:
    return read_document(path, logmap_from_dict)


def _scalar(table: Table, name: str, path: Path, what: str) -> float:
    """A constant of the file: a 1×1 variable, or a column that holds one value throughout."""
    if name in table.scalars:
        return table.scalars[name]
    column = table.columns.get(name)
    if column is not None and np.all(column == column[0]):
        return float(column[0])
    raise InputError(str(path), f"has no constant {name!r} (the log map's {what})")


def _read(table: Table, part: Column | Constant, role: Role, what: str, path: Path, n: int) -> np.ndarray:
    """One role's samples in its signal's unit."""
    factor = role.units[part.unit]
    if isinstance(part, Constant):
        return np.full(n, part.value * factor)
    values = table.numeric(part.column, path, f"the log map's {what}.column")
    if len(values) != n:
        raise InputError(f"{path}: {part.column}", f"has {len(values)} samples, the set point has {n}")
    if part.sign_bit is not None:  # sign and magnitude: at or above the bit one way, below it the other
        bit = part.sign_bit * (1.0 - SIGN_BIT_TOLERANCE)  # a register written through a float32 lands a hair below
        values = np.where(values >= bit, np.maximum(values - part.sign_bit, 0.0), -values)
    scale = part.scale if not isinstance(part.scale, str) else _scalar(table, part.scale, path, f"{what}.scale")
    return values * (1.0 if scale is None else scale) * factor * part.sign


def read_mapped(path: str | Path, log_map: LogMap) -> dict[str, Any]:
    """The ``ema-window/1`` document of one logged file, read through ``log_map``; InputError naming the file and
    the variable where they do not match."""
    path = Path(path)
    table = read_table(path, mapped_names(log_map))
    roles = KINDS[log_map.kind].roles
    n = len(table.numeric(log_map.set_point.column, path, "the log map's set_point"))
    signals: dict[str, np.ndarray] = {}
    for name, role in roles.items():
        part = log_map.part(name)
        if name == "position" and part is None:
            assert log_map.error is not None  # LogMap._complete
            error = _read(table, log_map.error, role, "error", path, n)
            signals[role.signal] = signals[roles["set_point"].signal] - error
        elif part is not None:
            signals[role.signal] = _read(table, part, role, name, path, n)
    resampled: dict[str, Any] = {}
    if log_map.time is None:
        assert log_map.sample_rate_hz is not None  # LogMap._complete
        rate = log_map.sample_rate_hz
    else:
        time_s = _read(table, log_map.time, Role("time_s"), "time", path, n)
        if not np.all(np.isfinite(time_s)):
            row = int(np.argmax(~np.isfinite(time_s)))
            raise InputError(f"{path}: {log_map.time.column}", f"the time variable holds {time_s[row]} at sample {row}")
        rate, signals, resampled = _uniform(time_s, signals, log_map.resample_hz, path)
    constants = {
        field: _scalar(table, variable, path, f"constants.{field}") for field, variable in log_map.constants.items()
    }
    return {
        "schema": "ema-window/1",
        "actuator_id": log_map.actuator_id,
        "window_id": window_id_of(path),
        "sample_rate_hz": float(rate),
        "flight_condition": None,
        "signals": {name: values.tolist() for name, values in signals.items()},
        **({"constants": constants} if constants else {}),
        **({"resampled": resampled} if resampled else {}),
    }


def mapped_names(log_map: LogMap) -> set[str]:
    """Every variable of a file ``log_map`` reads: its roles' columns and scales, its time, its constants."""
    names = set(log_map.constants.values())
    for part in (log_map.time, *(log_map.part(name) for name in ROLES)):
        if isinstance(part, Column):
            names.add(part.column)
            if isinstance(part.scale, str):
                names.add(part.scale)
    return names


def window_id_of(path: Path) -> str:
    """A logged file's window id: its name without the suffix; InputError naming the file where that is no id
    (printable ASCII, 1 to 200 characters: a name in another script, a name of blanks)."""
    if re.fullmatch(IDENTIFIER, path.stem) is None:
        shown = path.stem.encode("ascii", "backslashreplace").decode()
        raise InputError(
            str(path), f"its name {shown!r} is no window id (1-200 printable ASCII characters): rename the file"
        )
    return path.stem


def _uniform(
    time_s: np.ndarray, signals: dict[str, np.ndarray], resample_hz: float | None, path: Path
) -> tuple[float, dict[str, np.ndarray], dict[str, Any]]:
    """(rate, signals, how they were resampled): as logged where the time steps are uniform (``UNIFORM``), else
    resampled to ``resample_hz`` from the first time stamp (a switch's signal to its nearest sample, the others
    linearly); uneven steps without a rate to resample to are refused (``_rate``)."""
    steps = np.diff(time_s)
    if resample_hz is None or len(steps) == 0 or np.all(np.abs(steps - np.median(steps)) <= UNIFORM * np.median(steps)):
        return _rate(time_s, path), signals, {}
    if np.any(~np.isfinite(time_s)) or np.any(steps <= 0):
        row = int(np.argmax(~np.isfinite(steps) | (steps <= 0))) + 1
        raise InputError(str(path), f"its time variable does not increase after row {row}: it cannot be resampled")
    grid = time_s[0] + np.arange(int(np.floor((time_s[-1] - time_s[0]) * resample_hz)) + 1) / resample_hz
    after = np.clip(np.searchsorted(time_s, grid), 1, len(time_s) - 1)
    nearest = np.where(grid - time_s[after - 1] <= time_s[after] - grid, after - 1, after)
    resampled = {
        name: values[nearest] if units_of(name) is FLAG else np.interp(grid, time_s, values)
        for name, values in signals.items()
    }
    said = {"logged_samples": len(time_s), "min_step_s": float(steps.min()), "max_step_s": float(steps.max())}
    return float(resample_hz), resampled, said


def _rate(time_s: np.ndarray, path: Path) -> float:
    """The sample rate a time variable gives, where its steps are uniform (``UNIFORM``)."""
    steps = np.diff(time_s)
    if len(steps) == 0 or np.median(steps) <= 0:
        raise InputError(str(path), "its time variable does not increase")
    step = float(np.median(steps))
    if np.max(np.abs(steps - step)) > UNIFORM * step:
        worst = int(np.argmax(np.abs(steps - step)))
        raise InputError(
            str(path),
            f"is not uniformly sampled: its time steps by {steps[worst]:g} s after row "
            f"{worst + 1}, against {step:g} s elsewhere",
        )
    return 1.0 / step
