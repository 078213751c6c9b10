"""The ``ema-window/1`` flight-log window: read, write and validate (used by every layer)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sim.aircraft import FlightCondition
from sim.checks import InputError, finite_array, in_range

SCHEMA = "ema-window/1"
SIGNALS = ("command_deg", "position_deg", "motor_speed_radps", "current_a", "hinge_moment_nm")
MIN_SAMPLES = 100
MAX_SAMPLES = 1_000_000
WINDOW_RATE_RANGE_HZ = (1_000.0, 100_000.0)
# Physical plausibility: beyond these a sample is a sensor fault or a unit error, not a state.
SIGNAL_LIMITS = {
    "command_deg": (-40.0, 40.0),
    "position_deg": (-35.0, 35.0),
    "motor_speed_radps": (-2_000.0, 2_000.0),
    "current_a": (-60.0, 60.0),
    "hinge_moment_nm": (-5_000.0, 5_000.0),
}


@dataclass(frozen=True)
class Window:
    """A logged window: five uniformly sampled signals from t = 0 and where the aircraft flew."""

    signals: dict[str, np.ndarray]
    sample_rate_hz: float = 10_000.0
    flight_condition: FlightCondition = field(default_factory=FlightCondition)
    actuator_id: str = "unknown"
    window_id: str = "unknown"

    def __post_init__(self) -> None:
        in_range("sample_rate_hz", self.sample_rate_hz, *WINDOW_RATE_RANGE_HZ, "Hz")
        missing = [name for name in SIGNALS if name not in self.signals]
        if missing:
            raise InputError(f"signals.{missing[0]}", "is missing")
        unknown = sorted(set(self.signals) - set(SIGNALS))
        if unknown:
            raise InputError(f"signals.{unknown[0]}", f"is not a known signal; expected {', '.join(SIGNALS)}")
        arrays = {name: finite_array(f"signals.{name}", self.signals[name], ndim=1) for name in SIGNALS}
        length = len(arrays["command_deg"])
        for name, array in arrays.items():
            if len(array) != length:
                raise InputError(f"signals.{name}", f"has {len(array)} samples, command_deg has {length}")
            low, high = SIGNAL_LIMITS[name]
            outside = np.flatnonzero((array < low) | (array > high))
            if len(outside):
                raise InputError(
                    f"signals.{name}", f"sample {outside[0]} = {array[outside[0]]:g} is outside [{low:g}, {high:g}]"
                )
        if not MIN_SAMPLES <= length <= MAX_SAMPLES:
            raise InputError("signals", f"need {MIN_SAMPLES}..{MAX_SAMPLES} samples per signal, got {length}")
        object.__setattr__(self, "signals", arrays)

    @property
    def n_samples(self) -> int:
        return len(self.signals["command_deg"])

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.sample_rate_hz


def _require(document: dict[str, Any], key: str, kind: type | tuple[type, ...], prefix: str = "") -> Any:
    if key not in document:
        raise InputError(prefix + key, "is missing")
    value = document[key]
    if not isinstance(value, kind) or isinstance(value, bool):
        raise InputError(prefix + key, f"has the wrong type {type(value).__name__}")
    return value


def window_from_dict(document: Any) -> Window:
    """Parse and validate an ``ema-window/1`` document; errors name the field."""
    if not isinstance(document, dict):
        raise InputError("window", f"must be a JSON object, got {type(document).__name__}")
    schema = _require(document, "schema", str)
    if schema != SCHEMA:
        raise InputError("schema", f"unknown schema {schema!r}; expected {SCHEMA!r}")
    condition = _require(document, "flight_condition", dict)
    signals = _require(document, "signals", dict)
    return Window(
        signals={name: np.asarray(values) if isinstance(values, list) else values for name, values in signals.items()},
        sample_rate_hz=_require(document, "sample_rate_hz", (int, float)),
        flight_condition=FlightCondition(
            airspeed_mps=_require(condition, "airspeed_mps", (int, float), "flight_condition."),
            altitude_m=_require(condition, "altitude_m", (int, float), "flight_condition."),
        ),
        actuator_id=str(_require(document, "actuator_id", str)),
        window_id=str(_require(document, "window_id", str)),
    )


def window_to_dict(window: Window) -> dict[str, Any]:
    """The ``ema-window/1`` document of ``window``."""
    return {
        "schema": SCHEMA,
        "actuator_id": window.actuator_id,
        "window_id": window.window_id,
        "sample_rate_hz": window.sample_rate_hz,
        "flight_condition": {
            "airspeed_mps": window.flight_condition.airspeed_mps,
            "altitude_m": window.flight_condition.altitude_m,
        },
        "signals": {name: window.signals[name].tolist() for name in SIGNALS},
    }


def read_window(path: str | Path) -> Window:
    """Read one window from a JSON file; a bad file raises InputError naming it."""
    path = Path(path)
    try:
        document = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(str(path), f"cannot be read as JSON ({exc})") from None
    return window_from_dict(document)


def write_window(window: Window, path: str | Path) -> None:
    """Write ``window`` as JSON, atomically (a reader never sees half a file)."""
    path = Path(path)
    temporary = path.with_name(path.name + ".tmp")
    temporary.write_text(json.dumps(window_to_dict(window)))
    temporary.replace(path)
