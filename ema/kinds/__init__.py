"""Each kind of actuator whole, in one folder (after NASA progpy's ``PrognosticsModel``: a model declares what it
has, a predictor calls it).

A kind's documents (its window's signals, its actuator document's section, what its log map may name) are its
``ema.model.kinds.KindFacts``; its folder here adds the method, everything only that kind needs:

- ``ema.kinds.rotary``: the thesis's elevator EMA: its pipeline at 1 kHz or more (quasi-static below), its
  output-error check, its calibration loop that traces a residual to a missing effect, its synthetic windows;
- ``ema.kinds.linear``: a ball screw turned by a stepper, read quasi-statically at any rate, with its drive's
  calibration (learned from healthy runs, faulted runs compared with it);
- ``ema.kinds.servo``: a linear axis under a known position controller, logged on the load side, the whole
  method in the load frame (its log's reading, its inverse model, its closed-loop simulator and dataset, its
  stages, its calibration and effects);
- ``ema.kinds.geared``: a DC motor, a gear train and its own position loop, logged at the output shaft swinging a
  known load, the whole method there (its loop's simulator, its output-error reading, its dataset, its stages, its
  calibration and effects).

``estimate``, ``calibrate`` and ``cost`` are the entries the command line, the service and the fleet call; a
fourth kind is a folder here, a row of ``ema.model.kinds`` and a line in ``REGISTRY``, not branches in the stages.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from ema.calibration.truth import refuse_truth, with_truth_errors
from ema.estimate.config import PipelineConfig
from ema.estimate.documents import Estimate, Note
from ema.estimate.documents.window_facts import WindowInfo
from ema.estimate.information import out_of_bounds, refuse_empty_channels
from ema.kinds.base import NOTHING_LENT, Borrowed, Calibrated, CalibrationRequest, Cost, Kind, Lent, Request, SensorGain
from ema.kinds.geared import GEARED
from ema.kinds.linear import LINEAR
from ema.kinds.rotary import ROTARY
from ema.kinds.servo import SERVO
from ema.model.actuator import THESIS, ActuatorDocument
from ema.model.checks import InputError
from ema.model.document import Document
from ema.model.params import HealthParams
from ema.model.window import Window

__all__ = [
    "REGISTRY",
    "Borrowed",
    "Calibrated",
    "CalibrationRequest",
    "Cost",
    "Lent",
    "Request",
    "borrowed_document",
    "calibrate",
    "calibration_cost",
    "cost",
    "estimate",
    "estimate_thesis_window",
    "kind_of",
    "lacking",
    "learns",
    "lent_by",
    "load_methods",
    "other_windows_lent",
    "prognosis_lines",
    "prognosis_parts",
    "readings_of_results",
    "report_lines",
    "sensor_gains",
    "synthesize",
    "thesis_kernel_cached",
    "thesis_kernel_seconds",
    "thesis_window",
    "waits_for_the_run",
    "warm_up",
]


REGISTRY: dict[str, Kind] = {kind.facts.name: kind for kind in (ROTARY, LINEAR, SERVO, GEARED)}


def warm_up(names: Sequence[str] = tuple(REGISTRY)) -> None:
    """Each named kind warmed (``Kind.warm_up``): a service warms every kind before it answers."""
    for name in names:
        REGISTRY[name].warm_up()


def kind_of(actuator: ActuatorDocument) -> Kind:
    """The method of ``actuator``'s kind."""
    return REGISTRY[actuator.kind]


def same_kind(windows: Sequence[Window], actuator: ActuatorDocument, *, listed: bool = True) -> None:
    """InputError naming the first window whose signals are another kind's than the document's (``windows.i.signals``,
    or ``signals`` for a window posted alone: ``listed`` False)."""
    for i, window in enumerate(windows):
        if window.kind != actuator.kind:
            raise InputError(
                f"windows.{i}.signals" if listed else "signals",
                f"are a {window.kind} actuator's ({', '.join(window.signal_names)}), but the document "
                f"{actuator.name!r} is a {actuator.kind} one's: read window {window.window_id} with its own "
                "actuator's document",
            )


def estimate(
    window: Window,
    config: PipelineConfig = PipelineConfig(),
    *,
    actuator: ActuatorDocument,
    version: int | None = None,
    on_stage: Callable[[str], None] | None = None,
    history: Document | None = None,
    spec_only: bool = False,
) -> Estimate:
    """The ``ema-estimate/1`` result for ``window``, read by its actuator's kind; InputError where the window's
    signals are another kind's than its document's."""
    same_kind([window], actuator, listed=False)
    refuse_empty_channels(window)
    answer = kind_of(actuator).estimate(window, Request(config, actuator, version, on_stage, history, spec_only))
    held_to_document(answer, actuator)
    return answer


def held_to_document(answer: Estimate, actuator: ActuatorDocument) -> None:
    """InputError naming the first value of ``answer`` outside the bounds its document's field allows
    (``ema.estimate.information.out_of_bounds``): an answer outside them is never a reading."""
    values = {
        actuator.facts.document_field(name): entry.value
        for name in ("FDJ", "eta_O", "eta_A", "FSJ")
        if (entry := getattr(answer.estimates, name)) is not None
    }
    values |= {name: entry.value for name, entry in answer.estimates.constants.items()}
    out_of_bounds(values, actuator.bounding_classes, "estimates")


def calibrate(windows: Sequence[Window], request: CalibrationRequest) -> Calibrated:
    """``ema-calibration/1`` for windows of one actuator, by its kind; InputError naming a window of another
    kind or of another actuator."""
    if not windows:
        raise InputError("windows", "a calibration needs one window at least")
    same_kind(windows, request.actuator)
    for i, window in enumerate(windows):
        refuse_empty_channels(window, f"windows.{i}.signals")
        if window.actuator_id != windows[0].actuator_id:
            raise InputError(
                f"windows.{i}.actuator_id",
                f"is {window.actuator_id!r}; a calibration reads the windows of one actuator "
                f"({windows[0].actuator_id!r})",
            )
    if request.truth is not None:
        refuse_truth(request.truth, request.actuator)
    calibrated = kind_of(request.actuator).calibrate(windows, request)
    return replace(calibrated, report=with_truth_errors(calibrated.report, request.truth))


def learns(window: Window) -> bool:
    """Whether reading ``window`` trains a network, by its signals' kind (its ``stages``): a process that reads
    only windows that do not never loads the network's modules (SciPy's optimizers)."""
    return "learn" in REGISTRY[window.kind].stages(window)


def cost(window: Window, config: PipelineConfig) -> Cost:
    """What reading ``window`` asks of a service (``Cost``), by its signals' kind."""
    return REGISTRY[window.kind].cost(window, config)


def calibration_cost(windows: Sequence[Window], config: PipelineConfig) -> Cost:
    """What calibrating ``windows`` asks of a service beside reading each (``Cost``), by their kind."""
    return REGISTRY[windows[0].kind].calibration_cost(windows, config) if windows else Cost(0.0, 0.0)


# What the layers above reach of one kind's own, through the registry rather than the kind's modules: what an
# actuator's other windows lend one of its windows (``Kind.lent_by``, ``Kind.borrowed``: a rotary drive's sensor zero,
# kept for a power-on, and its J_M, kept with the build), a prognosis's and a report's own parts, the sensors' gains
# the prognosis trends, ema simulate's windows, and the thesis's own windows and kernel (the latency benchmark draws,
# reads and times them). Each kind imports its modules at their call: the registry stays light.


def lent_by(info: WindowInfo) -> Lent:
    """What a window's answer (its ``window`` part) lends the other windows of its actuator, as JSON: its kind's
    (each kind knows its answers' part by its class; one that lends nothing says ``NOTHING_LENT``)."""
    return next((lent for kind in REGISTRY.values() if (lent := kind.lent_by(info)) != NOTHING_LENT), NOTHING_LENT)


def waits_for_the_run(info: WindowInfo) -> bool:
    """Whether a window answered alone is answered again once its run's other windows are (``lacking``)."""
    return any(kind.waits_for_the_run(info) for kind in REGISTRY.values())


def other_windows_lent(actuator: ActuatorDocument, kept: Borrowed) -> Document | None:
    """What the kept loans of ``actuator``'s other windows lend one of its windows, as its kind reads them (None:
    its kind borrows nothing)."""
    return kind_of(actuator).borrowed(kept)


def borrowed_document(actuator: ActuatorDocument, data: Mapping[str, Any]) -> Document | None:
    """What a window borrows, as JSON (a fleet's worker is sent it), read as ``actuator``'s kind's class; None where
    its kind borrows nothing."""
    borrowing = kind_of(actuator).borrowing
    return None if borrowing is None else borrowing.model_validate(data)


def readings_of_results(
    actuator: ActuatorDocument, windows: Sequence[WindowInfo], flight_id: str | None
) -> Document | None:
    """What the results of other windows of an actuator (their ``window`` parts, oldest first) lend a window of
    ``flight_id``: to it, what those of its flight lent their flight, and what every one lent the actuator."""
    lent = [(info.flight_id, lent_by(info)) for info in windows]
    return other_windows_lent(
        actuator,
        Borrowed(
            from_flight=tuple(s.to_flight for f, s in lent if s.to_flight and flight_id is not None and f == flight_id),
            from_actuator=tuple(s.to_actuator for _, s in lent if s.to_actuator),
        ),
    )


def lacking(window: Window, read: WindowInfo, others: Document | None) -> Document | None:
    """What ``window``, answered alone (``read``), would be answered again with, of what the others lend (None:
    nothing it lacks)."""
    return REGISTRY[window.kind].lacking(read, others)


def sensor_gains() -> tuple[SensorGain, ...]:
    """Every kind's sensors' gains against a model, as their windows read them (``Kind.sensor_gains``)."""
    return tuple(gain for kind in REGISTRY.values() for gain in kind.sensor_gains)


def prognosis_parts(actuator: ActuatorDocument, infos: Sequence[WindowInfo]) -> tuple[dict[str, Any], list[Note]]:
    """``actuator``'s kind's own parts of a prognosis over its windows (oldest first), and notes beside them."""
    return kind_of(actuator).prognosis_parts(infos)


def prognosis_lines(prognosis: Mapping[str, Any]) -> list[str]:
    """The lines of a prognosis's own parts (as JSON), as the kind whose parts they are prints them (each kind prints
    its own and none of another's)."""
    return [line for kind in REGISTRY.values() for line in kind.prognosis_lines(prognosis)]


def thesis_window(health: HealthParams, **drawn: Any) -> Window:
    """A window of the thesis's elevator EMA drawn by its simulator (``ema.kinds.rotary.synthetic``)."""
    from ema.kinds.rotary.synthetic import synthetic_window

    return synthetic_window(health, **drawn)


def thesis_kernel_seconds(simulations: int, samples: int, rate_hz: float) -> tuple[float, int]:
    """The rotary simulator's kernel timed alone (``ema.kinds.rotary.simulator.timing``): (best seconds, lanes)."""
    from ema.kinds.rotary.simulator.timing import kernel_seconds

    return kernel_seconds(simulations, samples, rate_hz)


def thesis_kernel_cached() -> bool | None:
    """Whether Numba's cache holds the rotary simulator's kernel (None: unknown)."""
    from ema.kinds.rotary.simulator.timing import kernel_cached

    return kernel_cached()


def synthesize(actuator: ActuatorDocument, flags: Mapping[str, Any]) -> dict[str, Any]:
    """``ema simulate``: windows of ``actuator`` drawn by its kind's simulator, as ``flags`` ask (``Kind.synthesize``);
    InputError naming ``--actuator`` for a kind that draws none."""
    return kind_of(actuator).synthesize(actuator, flags)


def report_lines(report: Mapping[str, Any]) -> list[str]:
    """The lines of a calibration report's own parts, as its kind prints them (``Kind.report_lines``); a report
    written before reports named their kind is told by its parts (``kind_written``)."""
    from ema.calibration.documents import kind_written

    return REGISTRY[report.get("kind") or kind_written(dict(report))].report_lines(report)


def estimate_thesis_window(window: Window, config: PipelineConfig) -> Estimate:
    """The thesis's pipeline on a window of its actuator, in process (what the latency benchmark times)."""
    from ema.kinds.rotary.pipeline import estimate_window

    return estimate_window(window, config, actuator=THESIS)


def load_methods() -> None:
    """Every method module the default kind's first window would load, loaded now (a fork server's preload)."""
    import ema.kinds.rotary.pipeline  # noqa: F401
