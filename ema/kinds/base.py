"""What every kind of actuator declares (``Kind``) and the requests and answers its methods share."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from ema.calibration.documents import CalibrationReport
from ema.calibration.plot import ResidualPlot
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import ActuatorRead, Estimate, Note
from ema.estimate.documents.window_facts import WindowInfo
from ema.estimate.quasistatic.drive_torque import QuasiStaticReading
from ema.estimate.quasistatic.slow_window import estimate_low_rate
from ema.model.actuator import THESIS, ActuatorDocument
from ema.model.bounds import NOISE_COPIES
from ema.model.checks import InputError
from ema.model.document import Document
from ema.model.kinds import KindFacts, kinds_with
from ema.model.window import Window

WARM_UP = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=20, hidden_units=4)  # a warm-up's sizes


@dataclass(frozen=True)
class Request:
    """What a window is read with besides itself."""

    config: PipelineConfig
    actuator: ActuatorDocument
    version: int | None = None
    on_stage: Callable[[str], None] | None = None
    history: Document | None = None  # what its actuator's other windows lend it, as its kind reads it (Kind.borrowed)
    spec_only: bool = False

    @property
    def read_with(self) -> ActuatorRead:
        return ActuatorRead(name=self.actuator.name, version=self.version, default=self.actuator is THESIS)


@dataclass(frozen=True)
class CalibrationRequest:
    """What a calibration is run with besides its windows."""

    config: PipelineConfig
    actuator: ActuatorDocument
    truth: Mapping[str, float] | None = None
    copies: int = NOISE_COPIES
    on_stage: Callable[[str], None] | None = None
    checkpoint: Callable[[], None] | None = None


@dataclass(frozen=True)
class Calibrated:
    report: CalibrationReport
    completed: ActuatorDocument | None = None  # the document with what the runs taught (None: nothing to write)
    plot: ResidualPlot | None = None


@dataclass(frozen=True)
class Cost:
    """What a request asks of a service, in the units of its limits: the work of its simulations as seconds of
    the rotary simulator's 1 µs steps (a kind that simulates nothing: 0; a servo's steps at its controller's rate
    count as many 1 µs steps), and the window seconds its limit on a window's length (or a calibration's) holds
    (0: the kind's work does not grow with them beyond what its samples and its simulations say)."""

    simulated_s: float
    window_s: float


def read_quasi_statically(window: Window, request: Request, reading: QuasiStaticReading) -> Estimate:
    """``window`` read at constant-speed stretches, a drive's current as torque by ``reading``
    (``ema.estimate.quasistatic``): a kind's low-rate reading, as ``request`` asks it."""
    return estimate_low_rate(
        window,
        request.config,
        reading=reading,
        actuator=request.actuator,
        read_with=request.read_with,
        on_stage=request.on_stage,
    )


@dataclass(frozen=True)
class SensorGain:
    """A sensor's gain against a model of what it measures, as each window of a kind reads it: what the prognosis
    trends over an actuator's windows, and says where it stands off 1 or drifts."""

    name: str  # the trend's name, the window part's field
    signal: str  # the signal the sensor logs
    sensor: str  # for a person: "the hinge moment's strain gauge"
    model: str  # for a person: "the aircraft model"
    remedy: str  # what to do where it stands off the model
    read: Callable[[WindowInfo], tuple[float, float | None] | None]  # (gain, its std) a window read, or None


@dataclass(frozen=True)
class Lent:
    """What one window's answer lends its actuator's other windows, as JSON of its kind's own documents: to the
    windows of its flight (a rotary drive's sensor zero, kept for a power-on) and to every window of the actuator (its
    J_M, kept with the build); None where it lends nothing. The history keeps each in a column of its own."""

    to_flight: str | None = None
    to_actuator: str | None = None


NOTHING_LENT = Lent()


@dataclass(frozen=True)
class Borrowed:
    """What an actuator's other windows lent one of its windows, as kept (``Lent``'s JSON, oldest first): those of
    its flight's windows, and those every window of the actuator takes."""

    from_flight: tuple[str, ...] = ()
    from_actuator: tuple[str, ...] = ()


class LendsNothing:
    """The ``Kind`` methods of a kind whose windows read alone all they are read with: they lend nothing, borrow
    nothing, wait for no other, and its prognosis holds the shared parts alone."""

    borrowing: type[Document] | None = None

    def lent_by(self, info: WindowInfo) -> Lent:
        return NOTHING_LENT

    def borrowed(self, lent: Borrowed) -> Document | None:
        return None

    def waits_for_the_run(self, info: WindowInfo) -> bool:
        return False

    def lacking(self, read: WindowInfo, others: Document | None) -> Document | None:
        return None

    def prognosis_parts(self, infos: Sequence[WindowInfo]) -> tuple[dict[str, Any], list[Note]]:
        return {}, []

    def prognosis_lines(self, prognosis: Mapping[str, Any]) -> list[str]:
        return []


def learned_lines(learned: Sequence[Mapping[str, Any]], simulated: Mapping[str, float] | None = None) -> list[str]:
    """A report's learned constants for a person: each with its std and unit, and where ``simulated`` gives them, as
    the simulator takes them (what the completed document keeps)."""
    if not learned:
        return []
    beside = ": the solution's, and as the simulator takes them (what the document keeps)" if simulated else ""
    lines = [f"learned (one model){beside}:"]
    for entry in learned:
        kept = f"{simulated.get(entry['name'], entry['value']):>12.5g}  " if simulated else ""
        lines.append(f"  {entry['name']:<24}{entry['value']:>12.5g} ± {entry['std']:<10.2g}{kept}{entry['unit']}")
    return lines


def not_drawn(facts: KindFacts) -> InputError:
    """The refusal of a kind without a simulator of its own windows (``ema simulate``), naming the flag."""
    drawn = ", ".join(kinds_with("simulated"))
    return InputError("--actuator", f"is a {facts.name} actuator's document: ema simulate draws {drawn} windows only")


class Kind(Protocol):
    @property
    def facts(self) -> KindFacts: ...
    def stages(self, window: Window) -> tuple[str, ...]: ...
    def estimate(self, window: Window, request: Request) -> Estimate: ...
    def calibrate(self, windows: Sequence[Window], request: CalibrationRequest) -> Calibrated: ...
    def cost(self, window: Window, config: PipelineConfig) -> Cost: ...
    def calibration_cost(self, windows: Sequence[Window], config: PipelineConfig) -> Cost: ...
    def warm_up(self) -> None: ...  # what its first window would load, loaded now (a service before it answers)
    # ``ema simulate``: its windows drawn by its simulator as the flags ask; ``not_drawn`` where it has none
    def synthesize(self, actuator: ActuatorDocument, flags: Mapping[str, Any]) -> dict[str, Any]: ...
    # the sensors' gains its windows read against a model, for the prognosis to trend (none: its windows read none)
    @property
    def sensor_gains(self) -> tuple[SensorGain, ...]: ...
    # its own parts of an ``ema-calibration/1`` report (as JSON), as a person reads them
    def report_lines(self, report: Mapping[str, Any]) -> list[str]: ...
    # What its windows lend each other (``LendsNothing``: nothing). The class of what a window borrows (None: none),
    # what a window's answer lends, what the kept loans lend one window, whether a window answered alone is answered
    # again once its run's others are, and what it would be answered again with (None: nothing it lacks).
    @property
    def borrowing(self) -> type[Document] | None: ...
    def lent_by(self, info: WindowInfo) -> Lent: ...
    def borrowed(self, lent: Borrowed) -> Document | None: ...
    def waits_for_the_run(self, info: WindowInfo) -> bool: ...
    def lacking(self, read: WindowInfo, others: Document | None) -> Document | None: ...
    # its own parts of a prognosis over its windows (their ``window`` parts, oldest first) and notes beside them, and
    # those parts (as JSON) as a person reads them
    def prognosis_parts(self, infos: Sequence[WindowInfo]) -> tuple[dict[str, Any], list[Note]]: ...
    def prognosis_lines(self, prognosis: Mapping[str, Any]) -> list[str]: ...
