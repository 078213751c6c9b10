"""The fleet view's lines (``/ui``, ``GET /v1/actuators``): kept in the history, brought up to date on demand.

Each actuator's line (``ema.prognosis.status.summary``) is kept with the state of the history it was
computed from (its windows' count and last row, its document's version), so a line is recomputed only
after its actuator stored a window or a document, and a replica reads what another computed. Bringing
lines up to date is a job like an estimate: admitted through the queue, stopped between actuators
when its client leaves, and bounded in time (``ui_budget_s``). Lines it did not reach are shown as
they were, or as pending: a page never waits on a thousand prognoses. An actuator with fewer windows
than a forecast needs gets its line without one.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass

from starlette.concurrency import run_in_threadpool

from ema.history.open import History
from ema.model.actuator import THESIS
from ema.prognosis.documents import ActuatorSummary, Prognosis, Stored
from ema.prognosis.rul import MIN_WINDOWS as FORECAST_WINDOWS
from ema.prognosis.status import URGENCY, failed, summary
from ema.service.deps import safe_prognosis
from ema.service.jobs import JobRunner, OverloadedError


@dataclass(frozen=True)
class Lines:
    lines: list[ActuatorSummary]
    pending: list[str]  # actuators whose line could not be brought up to date in this request's budget


def _state(version: tuple[int, int, int]) -> str:
    return "{}:{}:{}".format(*version)


def _unit_of(latest: Stored | None) -> str:
    if latest is None or latest.window.flight_hours is not None:
        return "flight_hours"
    return "days" if latest.window.recorded_at is not None else "windows"


def refreshed(store: History, stale: list[tuple[str, str, int]], budget_s: float, cancel: threading.Event) -> set[str]:
    """Bring the lines of ``stale`` (actuator, state, windows) up to date within ``budget_s``, until ``cancel``;
    the actuators reached."""
    ids = [actuator_id for actuator_id, _, _ in stale]
    latest, documents = store.latest(ids), store.latest_documents(ids)
    deadline, done = time.monotonic() + budget_s, set()
    for actuator_id, state, windows in stale:
        if cancel.is_set() or time.monotonic() > deadline:
            break
        stored = documents.get(actuator_id)
        actuator, version = (THESIS, None) if stored is None else (stored.document, stored.version)
        last = latest.get(actuator_id)
        if windows >= FORECAST_WINDOWS:
            history, _ = store.history(actuator_id)
            prognosis = safe_prognosis(actuator_id, history, actuator, backtested=False)
        else:
            prognosis = Prognosis(actuator_id=actuator_id, time_unit=_unit_of(last), trends={}, remaining_life={})
        failure = next((n.text for n in prognosis.notes if n.code == "prognosis_failed"), None)
        line = (
            failed(actuator_id, windows, actuator, version, failure)
            if failure is not None
            else summary(prognosis, last, windows, actuator, version)
        )
        store.put_summary(actuator_id, state, URGENCY[line.status], line.soonest, line.model_dump_json())
        done.add(actuator_id)
    return done


def kept_lines(store: History) -> tuple[dict[str, ActuatorSummary], list[tuple[str, str, int]]]:
    """Every kept line, and the (actuator, state, windows) of those not up to date."""
    versions, kept = store.versions(), store.summaries()
    lines, stale = {}, []
    for actuator_id, version in versions.items():
        state, row = kept.get(actuator_id, ("", ""))
        if row:
            lines[actuator_id] = ActuatorSummary.model_validate_json(row)
        if state != _state(version):
            stale.append((actuator_id, _state(version), version[0]))
    return lines, stale


async def fleet_lines(store: History, runner: JobRunner, budget_s: float, gone: Callable[[], Awaitable[bool]]) -> Lines:
    """Every actuator's line, those out of date brought up to date first as far as the budget goes (as a job
    of the queue; where the queue is full, the lines as kept)."""
    lines, stale = await run_in_threadpool(kept_lines, store)
    if stale:
        try:
            with runner.admit() as ticket:
                await runner.run(ticket, gone, refreshed, store, stale, budget_s, ticket.cancel)
        except OverloadedError:
            pass  # the queue is full: the page shows what is kept, the rest pending
        lines, stale = await run_in_threadpool(kept_lines, store)
    for actuator_id, _, windows in stale:
        was = lines.get(actuator_id)
        reason = "its prognosis is being brought up to date: reload in a moment"
        lines[actuator_id] = (
            ActuatorSummary(actuator_id=actuator_id, status="pending", reason=reason, windows=windows, document="")
            if was is None
            else was.model_copy(update={"status": "pending", "reason": f"{reason} (was: {was.status})"})
        )
    return Lines(sorted(lines.values(), key=urgency), [actuator_id for actuator_id, _, _ in stale])


def urgency(line: ActuatorSummary) -> tuple[int, float, str]:
    soonest = line.soonest if line.soonest is not None else 1e300
    return URGENCY[line.status], soonest, line.actuator_id
