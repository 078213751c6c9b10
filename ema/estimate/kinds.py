"""The seam for a kind of actuator: its signals, which stages it runs, and how one of its windows becomes an
estimate (after NASA progpy's ``PrognosticsModel``: a model declares what it has, a predictor calls it).

- **rotary** (the thesis's elevator EMA: a current-piloted motor and a gear train): a window at 1 kHz or more
  goes through the whole pipeline (``ema.estimate.pipeline``); one logged slower is read quasi-statically
  (``ema.estimate.low_rate``), its torque k_T·I.
- **linear** (a ball screw turned by a stepper: a drive ema cannot simulate): read quasi-statically at any
  rate, its torque from the drive's current as ``ema calibrate`` learned it.

``estimate`` is the one entry the command line, the service and the fleet call. A second kind is a class
here with these three members, not branches in the stages.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import STAGES, ActuatorRead, Estimate
from ema.estimate.documents.window import HistoryReadings
from ema.estimate.low_rate import SKIPPED, estimate_low_rate
from ema.estimate.pipeline import estimate_window
from ema.model.actuator import THESIS, ActuatorDocument
from ema.model.checks import InputError
from ema.model.window import KIND_SIGNALS, Window

QUASI_STATIC = tuple(stage for stage in STAGES if stage not in SKIPPED)


@dataclass(frozen=True)
class Request:
    """What a window is read with besides itself."""

    config: PipelineConfig
    actuator: ActuatorDocument
    version: int | None = None
    on_stage: Callable[[str], None] | None = None
    history: HistoryReadings | None = None
    spec_only: bool = False

    @property
    def read_with(self) -> ActuatorRead:
        return ActuatorRead(name=self.actuator.name, version=self.version, default=self.actuator is THESIS)


class ActuatorKind(Protocol):
    @property
    def name(self) -> str: ...

    @property
    def signals(self) -> tuple[str, ...]: ...
    def stages(self, window: Window) -> tuple[str, ...]: ...
    def estimate(self, window: Window, request: Request) -> Estimate: ...


@dataclass(frozen=True)
class Rotary:
    name: str = "rotary"

    @property
    def signals(self) -> tuple[str, ...]:
        return KIND_SIGNALS[self.name]

    def stages(self, window: Window) -> tuple[str, ...]:
        return STAGES if window.high_rate else QUASI_STATIC

    def estimate(self, window: Window, request: Request) -> Estimate:
        if not window.high_rate:
            return estimate_low_rate(
                window,
                request.config,
                actuator=request.actuator,
                read_with=request.read_with,
                on_stage=request.on_stage,
            )
        return estimate_window(
            window,
            request.config,
            actuator=request.actuator,
            version=request.version,
            on_stage=request.on_stage,
            spec_only=request.spec_only,
            history=request.history,
        )


@dataclass(frozen=True)
class Linear:
    name: str = "linear"

    @property
    def signals(self) -> tuple[str, ...]:
        return KIND_SIGNALS[self.name]

    def stages(self, window: Window) -> tuple[str, ...]:
        return QUASI_STATIC

    def estimate(self, window: Window, request: Request) -> Estimate:
        return estimate_low_rate(
            window, request.config, actuator=request.actuator, read_with=request.read_with, on_stage=request.on_stage
        )


KINDS: dict[str, ActuatorKind] = {"rotary": Rotary(), "linear": Linear()}


def estimate(
    window: Window,
    config: PipelineConfig = PipelineConfig(),
    *,
    actuator: ActuatorDocument,
    version: int | None = None,
    on_stage: Callable[[str], None] | None = None,
    history: HistoryReadings | None = None,
    spec_only: bool = False,
) -> Estimate:
    """The ``ema-estimate/1`` result for ``window``, read by its actuator's kind; InputError where the window's
    signals are another kind's than its document's."""
    if window.kind != actuator.kind:
        raise InputError(
            "signals",
            f"are a {window.kind} actuator's ({', '.join(window.signal_names)}), but the "
            f"document {actuator.name!r} is of a {actuator.kind} one (its kind)",
        )
    request = Request(config, actuator, version, on_stage, history, spec_only)
    return KINDS[actuator.kind].estimate(window, request)
