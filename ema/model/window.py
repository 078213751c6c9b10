"""``ema-window/1``, the flight-log window every layer reads: one definition, one validation.

:class:`WindowDocument` is the JSON contract (``docs/model.md``, the window format): the service takes it
as its request body, the CLI and the replay client read files through it, and its JSON Schema
is exported to docs/schemas/. Types are strict (a boolean or a string is not a number), every
number finite, every bound stated in the schema. :class:`Window` is what the layers below
compute with: numpy arrays, built from a validated document or by our own code.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal, TypeVar

import numpy as np
from pydantic import (
    AwareDatetime,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    Tag,
    field_validator,
    model_validator,
)

from ema.model.aircraft import AIRSPEED_RANGE_MPS, ALTITUDE_RANGE_M, FlightCondition
from ema.model.bounds import (
    CLOCK_SKEW,
    CONSTANT_NAME,
    DEFAULT_SAMPLE_RATE_HZ,
    EARLIEST_RECORDED_AT,
    HIGH_RATE_HZ,
    IDENTIFIER,
    MAX_FLIGHT_HOURS,
    MAX_SAMPLES,
    MIN_SAMPLES,
    SIGNAL_LIMITS,
    WINDOW_RATE_RANGE_HZ,
    route_collision,
)
from ema.model.checks import InputError, read_document, validated
from ema.model.document import Number, refused_by
from ema.model.kinds import DEFAULT_KIND, KIND_NAMES, KINDS, kind_of_signals, nearest_kind

WINDOW_SCHEMA = "ema-window/1"
SIGNALS = KINDS[DEFAULT_KIND].signals  # the default kind's (a rotary window's)

Samples = Annotated[list[Number], Field(min_length=MIN_SAMPLES, max_length=MAX_SAMPLES)]


class _Contract(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class FlightConditionDocument(_Contract):
    airspeed_mps: Number = Field(ge=AIRSPEED_RANGE_MPS[0], le=AIRSPEED_RANGE_MPS[1], description="true airspeed")
    altitude_m: Number = Field(ge=ALTITUDE_RANGE_M[0], le=ALTITUDE_RANGE_M[1], description="pressure altitude, ISA")


class _Signals(_Contract):
    """Signals of one length, uniformly sampled from t = 0, each sample the mean over its interval: one kind's
    (``ema.model.kinds``), never a mix. Each kind's class lists its own."""

    kind: ClassVar[str]

    @model_validator(mode="before")
    @classmethod
    def _its_own_signals(cls, values: Any) -> Any:
        """A missing signal or another kind's named with what this kind's window carries (a null signal is
        absent, as the earlier document, which held every kind's signals, read it)."""
        if not isinstance(values, dict):
            return values
        values = {name: v for name, v in values.items() if v is not None}
        kind = KINDS[cls.kind]
        carries = f"a {kind.name} window carries {', '.join(kind.signals)}"
        missing = [name for name in kind.signals if name not in values]
        if missing:
            raise ValueError(f"{missing[0]}: is missing ({carries})")
        extra = [name for name in values if name not in kind.all_signals]
        if extra:
            raise ValueError(f"{extra[0]}: is no signal of it ({carries})")
        return values

    @field_validator("*")
    @classmethod
    def _plausible(cls, values: list[float] | None, info: Any) -> list[float] | None:
        if values is None:
            return None
        low, high = SIGNAL_LIMITS[info.field_name]
        array = np.asarray(values)
        outside = np.flatnonzero((array < low) | (array > high))
        if len(outside):
            index = int(outside[0])
            hint = ""
            if info.field_name == "motor_speed_radps" and np.all(np.abs(array) * np.pi / 30.0 <= high):
                hint = ": in rpm? (rad/s = rpm × π/30)"
            raise ValueError(f"sample {index} = {array[index]:g} is outside [{low:g}, {high:g}]{hint}")
        return values

    def arrays(self) -> dict[str, list[float]]:
        """Each signal the window carries, by name."""
        return {name: values for name in type(self).model_fields if (values := getattr(self, name)) is not None}


class RotarySignals(_Signals):
    """A rotary actuator's five signals."""

    kind: ClassVar[str] = "rotary"
    command_deg: Samples = Field(description=f"elevator command, within {SIGNAL_LIMITS['command_deg']}")
    position_deg: Samples = Field(description=f"deflection θ_u, within {SIGNAL_LIMITS['position_deg']}")
    motor_speed_radps: Samples = Field(description=f"motor speed ω_m, within {SIGNAL_LIMITS['motor_speed_radps']}")
    current_a: Samples = Field(description=f"the drive's current I, within {SIGNAL_LIMITS['current_a']}")
    hinge_moment_nm: Samples = Field(description=f"hinge moment H_e, within {SIGNAL_LIMITS['hinge_moment_nm']}")


class LinearSignals(_Signals):
    """A linear actuator's four signals."""

    kind: ClassVar[str] = "linear"
    command_mm: Samples = Field(description="the position set point [mm]")
    position_mm: Samples = Field(description="the measured position [mm]")
    current_a: Samples = Field(description=f"the drive's current I, within {SIGNAL_LIMITS['current_a']}")
    load_n: Samples = Field(description="the external force [N], positive pushing towards increasing position")


class ServoSignals(_Signals):
    """A servo's three signals on the load side, and its load where it has one."""

    kind: ClassVar[str] = "servo"
    set_point_m: Samples = Field(description="the position set point, on the load side [m]")
    position_m: Samples = Field(description="the measured position, on the load side [m]")
    drive_force_n: Samples = Field(
        description="the force the drive applies to the load [N]: its command times the drive's gain"
    )
    load_n: Samples | None = Field(
        None,
        description="the external force [N], positive pushing towards increasing position (a servo logged without "
        "one carries no load)",
    )


class GearedSignals(_Signals):
    """A geared servo's signals at its output shaft: its set point, its position, the duty its loop applied and the
    supply it applied it from, and whether its motor was on where the log records it."""

    kind: ClassVar[str] = "geared"
    set_point_rad: Samples = Field(description="the position set point at the output shaft [rad]")
    position_rad: Samples = Field(description="the measured position at the output shaft [rad], 0 hanging down")
    duty_ratio: Samples = Field(description="the PWM duty the loop applied, signed, a share of the supply (−1 to 1)")
    supply_v: Samples = Field(description="the supply the duty switches [V]")
    motor_on_flag: Samples | None = Field(
        None, description="1 where the motor's torque is enabled, 0 where it is off and the shaft turns free"
    )


def _signals_kind(signals: Any) -> str | None:
    """The tag ``SignalsDocument`` dispatches on: the kind whose signals these are, else the one they come closest
    to (whose class then names what is missing or foreign)."""
    if isinstance(signals, dict):
        names = [name for name, values in signals.items() if values is not None]
        return (kind_of_signals(names) or nearest_kind(names)).name
    return getattr(signals, "kind", None)


SignalsDocument = Annotated[
    Annotated[RotarySignals, Tag("rotary")]
    | Annotated[LinearSignals, Tag("linear")]
    | Annotated[ServoSignals, Tag("servo")]
    | Annotated[GearedSignals, Tag("geared")],
    Discriminator(_signals_kind),
]  # one kind's signals, told by which it carries


class ResamplingDocument(_Contract):
    """How a log with uneven time stamps became this uniformly sampled window (its reader resampled it)."""

    logged_samples: int = Field(ge=2, le=MAX_SAMPLES, description="the samples the log held")
    min_step_s: Number = Field(ge=0, description="its shortest time step")
    max_step_s: Number = Field(gt=0, description="its longest time step")


class WindowDocument(_Contract):
    """``ema-window/1``."""

    schema_: Literal["ema-window/1"] = Field(alias="schema")
    actuator_id: Annotated[str, refused_by(route_collision)] = Field(
        min_length=1, max_length=200, pattern=IDENTIFIER, examples=["tail-123/elevator-left"]
    )
    window_id: str = Field(min_length=1, max_length=200, pattern=IDENTIFIER, examples=["2026-11-21T10:00:00Z#17"])
    sample_rate_hz: Number = Field(ge=WINDOW_RATE_RANGE_HZ[0], le=WINDOW_RATE_RANGE_HZ[1])
    flight_condition: FlightConditionDocument | None = Field(
        None,
        description="where the aircraft flew; null or absent: logged on the ground (a pre-flight test or a "
        "bench), where no aircraft model applies and the logged hinge moment is the load",
    )
    signals: SignalsDocument
    recorded_at: AwareDatetime | None = Field(
        None,
        description=f"when the window began (for trends), from {EARLIEST_RECORDED_AT.date()} to a day past the "
        "receiver's clock",
    )
    flight_hours: Number | None = Field(
        None, ge=0, le=MAX_FLIGHT_HOURS, description="the airframe's flight hours then (for trends)"
    )
    flight_id: str | None = Field(
        None,
        min_length=1,
        max_length=200,
        pattern=IDENTIFIER,
        description="the flight (one power-on of the drive) it was logged in: a window moving one way, which "
        "cannot read its sensors' zero, is read with the zero of one of the same flight that moves both ways",
        examples=["tail-123/2026-11-21T10:00:00Z"],
    )

    resampled: ResamplingDocument | None = Field(
        None,
        description="where the log's own time stamps were uneven and its reader resampled it to sample_rate_hz: "
        "their steps (null: logged at this rate)",
    )
    constants: dict[Annotated[str, Field(pattern=CONSTANT_NAME)], Number] | None = Field(
        None,
        max_length=64,
        description="constants the log recorded beside its signals, under the names of the actuator document's "
        "section (a servo's controller gains): read with the document, which must agree where it gives them too",
    )

    @field_validator("recorded_at")
    @classmethod
    def _recorded_in_time(cls, value: dt.datetime | None) -> dt.datetime | None:
        if value is not None and not EARLIEST_RECORDED_AT <= value <= dt.datetime.now(dt.UTC) + CLOCK_SKEW:
            raise ValueError(f"{value.isoformat()} is before {EARLIEST_RECORDED_AT.date()} or over a day ahead of now")
        return value

    def to_window(self) -> Window:
        """The arrays; signals of unequal lengths are refused naming the first one that differs."""
        arrays = {name: np.asarray(values, dtype=np.float64) for name, values in self.signals.arrays().items()}
        first = next(iter(arrays))
        for name, array in arrays.items():
            if len(array) != len(arrays[first]):
                raise InputError(f"signals.{name}", f"has {len(array)} samples, {first} has {len(arrays[first])}")
        kind = kind_of_signals(arrays)
        for name in self.constants or {}:
            if kind is not None and (why := kind.recorded_field(name)) is not None:
                raise InputError(f"constants.{name}", why)
        flight = self.flight_condition
        condition = None if flight is None else FlightCondition(flight.airspeed_mps, flight.altitude_m)
        recorded = None if self.recorded_at is None else self.recorded_at.isoformat()
        steps = self.resampled
        resampled = None if steps is None else Resampling(steps.logged_samples, steps.min_step_s, steps.max_step_s)
        return Window(
            arrays,
            self.sample_rate_hz,
            condition,
            self.actuator_id,
            self.window_id,
            recorded_at=recorded,
            flight_hours=self.flight_hours,
            flight_id=self.flight_id,
            constants=dict(self.constants or {}),
            resampled=resampled,
        )


@dataclass(frozen=True)
class Resampling:
    """A log of uneven time steps resampled to the window's rate: how many samples it held, its steps' range [s]."""

    logged_samples: int
    min_step_s: float
    max_step_s: float


@dataclass(frozen=True)
class Window:
    """A logged window as arrays: its kind's signals, uniformly sampled from t = 0, and where the aircraft flew (None:
    on the ground). Built as ``Window(signals, ...)`` it is its kind's class (``RotaryWindow``, ``LinearWindow``,
    ``ServoWindow``, ``GearedWindow``, told by its signals once): a kind's code takes its own, and says so."""

    KIND: ClassVar[str | None] = None  # each kind's class: its name

    signals: dict[str, np.ndarray]
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ
    flight_condition: FlightCondition | None = field(default_factory=FlightCondition)
    actuator_id: str = "unknown"
    window_id: str = "unknown"
    recorded_at: str | None = None  # ISO 8601 with a time zone
    flight_hours: float | None = None
    flight_id: str | None = None  # one power-on of the drive: its sensors keep one zero
    constants: dict[str, float] = field(default_factory=dict)  # what the log recorded beside its signals
    resampled: Resampling | None = None  # a log of uneven time steps, resampled to sample_rate_hz

    def __new__(cls, *args: Any, **kwargs: Any) -> Window:
        """The window as its kind's class where built as ``Window``: the kind its signals are (no one kind's: the
        shared class, whose ``kind`` says why)."""
        signals = args[0] if args else kwargs.get("signals")
        if cls is Window and signals is not None and (found := kind_of_signals(signals)) is not None:
            cls = WINDOW_CLASSES[found.name]
        return super().__new__(cls)

    def __post_init__(self) -> None:
        if self.KIND is not None and kind_of_signals(self.signals) is not KINDS[self.KIND]:
            raise InputError("signals", f"{', '.join(self.signals)} are not a {self.KIND} actuator's signals")
        lengths = {name: len(self.signals[name]) for name in self.signal_names}
        if len(set(lengths.values())) != 1:
            raise InputError("signals", f"signals differ in length: {lengths}")

    @property
    def kind(self) -> str:
        """The kind whose signals these are (``ema.model.kinds``)."""
        if self.KIND is not None:
            return self.KIND
        raise InputError("signals", f"{', '.join(self.signals)} are no one kind's signals")

    @property
    def signal_names(self) -> tuple[str, ...]:
        """The signals the window carries, in its kind's order."""
        return tuple(name for name in KINDS[self.kind].all_signals if name in self.signals)

    @property
    def high_rate(self) -> bool:
        """Logged fast enough for the whole pipeline (``HIGH_RATE_HZ``); else read quasi-statically."""
        return self.sample_rate_hz >= HIGH_RATE_HZ

    @property
    def n_samples(self) -> int:
        return len(self.signals[self.signal_names[0]])

    def content_sha256(self) -> str:
        """SHA-256 of everything the window says but its key (actuator_id, window_id): two bodies posted
        under one key are the same window exactly when their digests agree."""
        digest = hashlib.sha256()
        meta = window_to_dict(replace(self, signals={name: self.signals[name][:0] for name in self.signal_names}))
        for key in ("actuator_id", "window_id", "signals"):
            meta.pop(key)
        digest.update(json.dumps(meta, sort_keys=True).encode())
        for name in self.signal_names:
            digest.update(np.ascontiguousarray(self.signals[name], dtype="<f8").tobytes())
        return digest.hexdigest()

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.sample_rate_hz

    @property
    def on_ground(self) -> bool:
        return self.flight_condition is None


@dataclass(frozen=True)
class RotaryWindow(Window):
    """A rotary actuator's window: command, deflection, motor speed, current and hinge moment."""

    KIND: ClassVar[str | None] = "rotary"


@dataclass(frozen=True)
class LinearWindow(Window):
    """A ball screw's window: its set point, position, current and load."""

    KIND: ClassVar[str | None] = "linear"


@dataclass(frozen=True)
class ServoWindow(Window):
    """A servo's window on the load side: its set point, position, drive force (and load)."""

    KIND: ClassVar[str | None] = "servo"


@dataclass(frozen=True)
class GearedWindow(Window):
    """A geared servo's window at its output: set point, position, duty and supply (and the motor's on flag)."""

    KIND: ClassVar[str | None] = "geared"


WINDOW_CLASSES: dict[str, type[Window]] = {
    cls.KIND: cls for cls in (RotaryWindow, LinearWindow, ServoWindow, GearedWindow) if cls.KIND
}
KindWindow = TypeVar("KindWindow", bound=Window)


def as_window(window: Window, kind: type[KindWindow]) -> KindWindow:
    """``window`` as ``kind``'s class (a kind's method reading its own signals); InputError naming the signals where
    the window is another kind's."""
    if not isinstance(window, kind):
        raise InputError("signals", f"are a {window.kind} actuator's: this reads a {kind.KIND} actuator's window")
    return window


def window_from_dict(document: Any) -> Window:
    """Parse and validate an ``ema-window/1`` document (a dict); errors name the field."""
    return validated(WindowDocument, document, "window", tags=KIND_NAMES).to_window()


def window_to_dict(window: Window) -> dict[str, Any]:
    """The ``ema-window/1`` document of ``window``."""
    return {
        "schema": WINDOW_SCHEMA,
        "actuator_id": window.actuator_id,
        "window_id": window.window_id,
        "sample_rate_hz": float(window.sample_rate_hz),
        "flight_condition": None
        if window.flight_condition is None
        else {
            "airspeed_mps": float(window.flight_condition.airspeed_mps),
            "altitude_m": float(window.flight_condition.altitude_m),
        },
        "signals": {name: window.signals[name].tolist() for name in window.signal_names},
        **({"recorded_at": window.recorded_at} if window.recorded_at is not None else {}),
        **({"flight_hours": window.flight_hours} if window.flight_hours is not None else {}),
        **({"flight_id": window.flight_id} if window.flight_id is not None else {}),
        **({"constants": dict(window.constants)} if window.constants else {}),
        **({"resampled": asdict(window.resampled)} if window.resampled is not None else {}),
    }


def read_window(path: str | Path) -> Window:
    """Read one window from a JSON file; a bad file raises InputError naming it (and the field)."""
    return read_document(path, window_from_dict)


def write_window(window: Window, path: str | Path) -> None:
    """Write ``window`` as JSON, atomically (a reader never sees half a file)."""
    path = Path(path)
    temporary = path.with_name(path.name + ".tmp")
    try:
        temporary.write_text(json.dumps(window_to_dict(window)))
    except OSError as error:  # said of the file asked for, not of its temporary twin
        raise OSError(error.errno, error.strerror, str(path)) from None
    temporary.replace(path)
