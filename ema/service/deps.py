"""Shared request dependencies: settings, the history, the job runner, a request's pipeline sizes, the path's
actuator id, and an actuator's prognosis (one actuator's failure is its own, never the fleet's)."""

from __future__ import annotations

import logging
import re
import threading
import urllib.parse
from collections import OrderedDict
from collections.abc import Callable, Sequence
from typing import Annotated

from fastapi import Depends, Path, Request
from starlette.concurrency import run_in_threadpool

from ema.estimate.config import PipelineConfig
from ema.estimate.documents import Note
from ema.history.open import History
from ema.kinds import same_kind
from ema.model.actuator import THESIS, ActuatorDocument
from ema.model.bounds import IDENTIFIER, route_collision
from ema.model.checks import InputError, validated
from ema.model.window import Window
from ema.prognosis.documents import Prognosis, Stored
from ema.prognosis.prognose import prognose
from ema.service.config import Settings
from ema.service.jobs import CancelledError, JobRunner

log = logging.getLogger("ema.service")
IDENTIFIER_RE = re.compile(IDENTIFIER)


def get_settings(request: Request) -> Settings:
    settings: Settings = request.app.state.settings
    return settings


def get_store(request: Request) -> History:
    store: History = request.app.state.store
    return store


def get_runner(request: Request) -> JobRunner:
    runner: JobRunner = request.app.state.runner
    return runner


def path_actuator_id(actuator_id: Annotated[str, Path(description="as in the window's actuator_id")]) -> str:
    """The path's actuator id, under the rule of a window's ``actuator_id`` (printable ASCII, 1–200, no
    surrounding blanks): a NUL, an RTL override or 10,000 characters are refused, never stored."""
    if not 1 <= len(actuator_id) <= 200 or not IDENTIFIER_RE.match(actuator_id):
        shown = actuator_id[:40].encode("unicode_escape").decode()
        raise InputError("path.actuator_id", f"{shown!r} is not an actuator id (1–200 printable ASCII characters)")
    clash = route_collision(actuator_id)
    if clash is not None:
        raise InputError("path.actuator_id", f"{actuator_id!r} {clash}")
    return actuator_id


SettingsDep = Annotated[Settings, Depends(get_settings)]
StoreDep = Annotated[History, Depends(get_store)]
RunnerDep = Annotated[JobRunner, Depends(get_runner)]
ActuatorId = Annotated[str, Depends(path_actuator_id)]

CEILINGS = {"n_simulations": "max_simulations", "n_timesteps": "max_timesteps", "hidden_units": "max_hidden_units"}


def request_config(settings: Settings, **overrides: int | None) -> PipelineConfig:
    """The service's pipeline sizes with a request's overrides, each within the service's ceiling."""
    given = {name: value for name, value in overrides.items() if value is not None}
    for name, value in given.items():
        ceiling = getattr(settings, CEILINGS.get(name, ""), None)
        if ceiling is not None and value > ceiling:
            raise InputError(f"query.{name}", f"{value} exceeds this service's limit of {ceiling}")
    return validated(PipelineConfig, {**settings.pipeline.model_dump(), **given}, "query", prefix="query.")


async def is_stored(store: History, actuator_id: str) -> bool:
    """Whether a window or a document of ``actuator_id`` is stored: where none is, its history and its page are a
    404 (an id mistyped is never shown as an actuator with no windows)."""
    return actuator_id in await run_in_threadpool(store.actuator_ids)


def document_of(store: History, actuator_id: str) -> tuple[ActuatorDocument, int | None]:
    """The actuator's latest stored document and its version, or the default (``ema.model.actuator.THESIS``, no
    version) where it has none: its windows are then read with the default, and their answers say so."""
    stored = store.get_actuator(actuator_id)
    return (THESIS, None) if stored is None else (stored.document, stored.version)


async def actuator_of(store: History, actuator_id: str) -> tuple[ActuatorDocument, int | None]:
    return await run_in_threadpool(document_of, store, actuator_id)


def stored_kind(windows: Sequence[Window], actuator: ActuatorDocument, version: int | None, *, listed: bool) -> None:
    """``ema.kinds.same_kind`` where the actuator has no stored document, its refusal saying how to store one:
    read with the default, a window of another kind is refused as that only (``listed``: ``windows.i.signals``,
    else ``signals`` for a window posted alone)."""
    if version is not None:
        return  # a stored document: the kind's own run checks its windows against it
    try:
        same_kind(windows, actuator, listed=listed)
    except InputError as exc:
        actuator_id = windows[0].actuator_id
        path = f"/v1/actuators/{urllib.parse.quote(actuator_id, safe='/')}"
        raise InputError(
            exc.field,
            f"{exc.message}; no ema-actuator/1 document is stored for {actuator_id!r} (the default is used): PUT "
            f"its document to {path} first (ema replay --actuator A.json does)",
        ) from None


def safe_prognosis(
    actuator_id: str, history: list[Stored], actuator: ActuatorDocument, *, backtested: bool = True
) -> Prognosis:
    """``prognose``, or a prognosis that says it failed and why: one actuator's numbers never take the view
    down for the others."""
    try:
        return prognose(actuator_id, history, actuator, backtested=backtested)
    except Exception as exc:  # any failure of the numerics is this actuator's, reported on its own row
        log.exception("prognosis of %s failed", actuator_id)
        note = Note(code="prognosis_failed", text=f"the prognosis could not be computed: {type(exc).__name__}: {exc}")
        return Prognosis(actuator_id=actuator_id, time_unit="windows", trends={}, remaining_life={}, notes=[note])


class Prognoses:
    """The latest prognoses, each kept while its actuator's history and document stand (a prognosis with its
    backtest takes seconds on a long history)."""

    def __init__(self, size: int = 64) -> None:
        self.size = size
        self._kept: OrderedDict[tuple[str, int, int | None, int | None], Prognosis] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: tuple[str, int, int | None, int | None]) -> Prognosis | None:
        with self._lock:
            found = self._kept.get(key)
            if found is not None:
                self._kept.move_to_end(key)
            return found

    def put(self, key: tuple[str, int, int | None, int | None], prognosis: Prognosis) -> None:
        with self._lock:
            self._kept[key] = prognosis
            while len(self._kept) > self.size:
                self._kept.popitem(last=False)


def prognosis_now(prognoses: Prognoses, store: History, actuator_id: str) -> tuple[Prognosis, list[Stored]]:
    """The actuator's prognosis over its stored estimates to its document's thresholds (kept while they stand),
    and those estimates; in a worker thread."""
    current, _ = store.history(actuator_id)
    document, version = document_of(store, actuator_id)
    key = (actuator_id, len(current), current[-1].id if current else None, version)
    found = prognoses.get(key)
    if found is None:
        found = safe_prognosis(actuator_id, current, document)
        prognoses.put(key, found)
    return found, current


def stopper(cancel: threading.Event) -> Callable[[str], None]:
    """An ``on_stage`` callback that stops the job at its next stage once ``cancel`` is set."""

    def on_stage(_: str) -> None:
        if cancel.is_set():
            raise CancelledError("the client left; stopped before the next stage")

    return on_stage
