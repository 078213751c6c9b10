"""The fleet view's lines (``/ui``, ``GET /v1/actuators``): kept in the history, brought up to date by a worker of
their own.

Each actuator's line (``ema.prognosis.status.summary``) is kept with the state of the history it was computed from
(its windows' count and last row, its document's version) and of the code that computed it (``rules``), so a line is
recomputed only after its actuator stored a window or a document, or ema's rules changed, and a replica reads what
another computed. A page only reads the kept lines (those out of date shown as they were, or as pending), through
one shared reading (``FleetView``): it never computes, so people looking at the fleet take nothing from the
estimates. The ``LineKeeper`` brings lines up to date on a thread of its own, woken when a window or a document is
stored (and every ``KEEPER_PERIOD_S``, for what another replica or ``ema fleet`` stored), one actuator at a time,
and only once no job has run or waited for ``KEEPER_QUIET_S``: a client posting windows one after another finds the
cores as the last post left them, not shared with a line of the window just stored. Under a stream without such a
pause, one line is brought up to date every ``KEEPER_MAX_WAIT_S``, so that the view is never further behind. An
actuator with fewer windows than a forecast needs gets its line without one.
"""

from __future__ import annotations

import functools
import hashlib
import logging
import math
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from ema.history.open import History
from ema.model.actuator import THESIS, ActuatorDocument
from ema.prognosis.documents import ActuatorSummary, Prognosis, Stored
from ema.prognosis.rul import MIN_TREND_WINDOWS
from ema.prognosis.status import URGENCY, failed, summary
from ema.service.deps import safe_prognosis
from ema.service.jobs import JobRunner

log = logging.getLogger("ema.service")
KEEPER_PERIOD_S = 5.0  # the keeper looks for lines out of date at least this often
KEEPER_QUIET_S = 0.5  # a line waits until no job has run or waited for this long
KEEPER_MAX_WAIT_S = 30.0  # ... or until it has waited this long for such a pause
IDLE_POLL_S = 0.05  # how often a keeper that yielded looks whether the service is quiet again
VIEW_MAX_AGE_S = 1.0  # lines another replica or ``ema fleet`` stored show on a page within this


@dataclass(frozen=True)
class Lines:
    lines: list[ActuatorSummary]
    pending: list[str]  # actuators whose line could not be brought up to date in this request's budget


def _state(version: tuple[int, int, int]) -> str:
    return "{}:{}:{}:".format(*version) + rules()


@functools.cache
def rules() -> str:
    """A digest of the code a line is computed by (the prognosis, the document's levels and healthy ranges): a line
    an earlier ema kept is out of date after an upgrade, as one kept before a window was stored is."""
    import ema.model.actuator
    import ema.prognosis

    files = [*sorted(Path(ema.prognosis.__file__).parent.glob("*.py")), Path(ema.model.actuator.__file__)]
    digest = hashlib.sha256()
    for file in files:
        digest.update(file.read_bytes())
    return digest.hexdigest()[:16]


def _unit_of(latest: Stored | None) -> str:
    if latest is None or latest.window.flight_hours is not None:
        return "flight_hours"
    return "days" if latest.window.recorded_at is not None else "windows"


def refreshed(store: History, stale: list[tuple[str, str, int]], cancel: threading.Event) -> set[str]:
    """Bring the lines of ``stale`` (actuator, state, windows) up to date, until ``cancel``; the actuators
    reached."""
    ids = [actuator_id for actuator_id, _, _ in stale]
    latest, documents = store.latest(ids), store.latest_documents(ids)
    done = set()
    for actuator_id, state, windows in stale:
        if cancel.is_set():
            break
        stored = documents.get(actuator_id)
        actuator, version = (THESIS, None) if stored is None else (stored.document, stored.version)
        last = latest.get(actuator_id)
        if windows >= MIN_TREND_WINDOWS:
            history, _ = store.history(actuator_id)
            prognosis = safe_prognosis(actuator_id, history, actuator, backtested=False)
        else:
            prognosis = Prognosis(actuator_id=actuator_id, time_unit=_unit_of(last), trends={}, remaining_life={})
        line = _line(prognosis, last, windows, actuator, version)
        store.put_summary(actuator_id, state, URGENCY[line.status], line.soonest, line.model_dump_json())
        done.add(actuator_id)
    return done


def _line(
    prognosis: Prognosis, last: Stored | None, windows: int, actuator: ActuatorDocument, version: int | None
) -> ActuatorSummary:
    """The actuator's line, or one that says its prognosis failed and why: one actuator's numbers never keep the
    lines of the others from being brought up to date."""
    failure = next((n.text for n in prognosis.notes if n.code == "prognosis_failed"), None)
    if failure is None:
        try:
            return summary(prognosis, last, windows, actuator, version)
        except Exception as exc:  # any failure of the numerics is this actuator's, reported on its own line
            log.exception("the line of %s failed", prognosis.actuator_id)
            failure = f"its line could not be computed: {type(exc).__name__}: {exc}"
    return failed(prognosis.actuator_id, windows, actuator, version, failure)


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


def fleet_lines(store: History) -> Lines:
    """Every actuator's line as kept, those out of date marked pending (the ``LineKeeper`` is at them)."""
    lines, stale = kept_lines(store)
    for actuator_id, _, windows in stale:
        was = lines.get(actuator_id)
        reason = "its prognosis is being brought up to date: reload in a moment"
        lines[actuator_id] = (
            ActuatorSummary(actuator_id=actuator_id, status="pending", reason=reason, windows=windows, document="")
            if was is None
            else was.model_copy(update={"status": "pending", "reason": f"{reason} (was: {was.status})"})
        )
    return Lines(sorted(lines.values(), key=urgency), [actuator_id for actuator_id, _, _ in stale])


class FleetView:
    """The fleet's lines as last read from the history, shared by every page and list: read again only once
    ``VIEW_MAX_AGE_S`` has passed or this service stored a window, a document or a line, and by one reader at a
    time. Five viewers reloading as fast as they can then cost one read a second, not five reads a reload."""

    def __init__(self, store: History) -> None:
        self.store = store
        self._lock = threading.Lock()
        self._lines: Lines | None = None
        self._read_at = -math.inf

    def out_of_date(self) -> None:
        """Something was stored: the next page reads the history again."""
        self._read_at = -math.inf

    def lines(self) -> Lines:
        with self._lock:
            if self._lines is None or time.monotonic() - self._read_at >= VIEW_MAX_AGE_S:
                self._read_at = time.monotonic()  # before the read: a store during it marks it out of date
                self._lines = fleet_lines(self.store)
            return self._lines


class LineKeeper:
    """The fleet's lines brought up to date on a thread of its own, yielding to every job (module docstring)."""

    def __init__(self, store: History, runner: JobRunner, view: FleetView) -> None:
        self.store, self.runner, self.view = store, runner, view
        self._wake, self._stop = threading.Event(), threading.Event()
        self._thread = threading.Thread(target=self._loop, name="ema-lines", daemon=True)

    def start(self) -> None:
        self._wake.set()  # a pass at start: lines a restart left stale
        self._thread.start()

    def poke(self) -> None:
        """A window or a document was stored: its actuator's line is out of date."""
        self.view.out_of_date()
        self._wake.set()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=10)

    def _loop(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(KEEPER_PERIOD_S)
            self._wake.clear()
            try:
                self._pass()
            except Exception:  # a history that cannot be read now: the next wake tries again
                log.warning("the fleet's lines could not be brought up to date", exc_info=True)

    def _pass(self) -> None:
        for item in kept_lines(self.store)[1]:
            waiting_since = time.monotonic()
            while not self._stop.is_set() and self.runner.quiet_for() < KEEPER_QUIET_S:
                if time.monotonic() - waiting_since >= KEEPER_MAX_WAIT_S:
                    break  # a stream without a pause: this line now, beside it
                time.sleep(IDLE_POLL_S)  # jobs run or ran a moment ago: they have the cores
            if self._stop.is_set():
                return
            refreshed(self.store, [item], self._stop)
            self.view.out_of_date()


def urgency(line: ActuatorSummary) -> tuple[int, float, str]:
    soonest = line.soonest if line.soonest is not None else 1e300
    return URGENCY[line.status], soonest, line.actuator_id
