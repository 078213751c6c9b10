"""The history of every answered estimate: SQLite, one row per (actuator_id, window_id).

- Committed (``synchronous=FULL``, WAL) before the answer leaves: an estimate a client has
  received survives a kill -9 of the server or a power loss.
- Idempotent: the same window posted again returns the stored answer; the trend counts it once.
- What windows read that another may not (``readings``): its flight's sensor zero, the actuator's J_M.
- Private: the file is created 0600 (SQLite gives its WAL and shared-memory files the same mode).
- Checked at start: a file that is not an intact SQLite database is refused with the reason,
  never silently replaced (nothing a user stored is lost); ``healthy()`` answers /healthz.
- A history written by an earlier version (rows without the key) is migrated: its table is kept
  as ``estimates_v1`` and its rows copied once each, oldest first; rows in the old result format
  are returned as ``legacy``, as stored.
"""

from __future__ import annotations

import datetime as dt
import json
import logging
import os
import sqlite3
import threading
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from ema.calibration.documents import CalibrationReport
from ema.estimate.documents import Estimate, HistoryReadings, InertiaReading, SensorZero
from ema.estimate.history import lent
from ema.model.actuator import Actuator
from ema.prognosis.documents import Stored, StoredActuator

log = logging.getLogger("ema.service")

SCHEMA_SQL = """
CREATE TABLE IF NOT EXISTS estimates (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    actuator_id TEXT NOT NULL,
    window_id TEXT NOT NULL,
    stored_at TEXT NOT NULL,
    result TEXT NOT NULL,
    content_sha256 TEXT,
    UNIQUE (actuator_id, window_id)
);
CREATE INDEX IF NOT EXISTS estimates_by_actuator ON estimates (actuator_id, id);
CREATE TABLE IF NOT EXISTS calibrations (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    actuator_id TEXT NOT NULL,
    stored_at TEXT NOT NULL,
    report TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS calibrations_by_actuator ON calibrations (actuator_id, id);
CREATE TABLE IF NOT EXISTS actuators (
    actuator_id TEXT NOT NULL,
    version INTEGER NOT NULL,
    stored_at TEXT NOT NULL,
    document TEXT NOT NULL,
    PRIMARY KEY (actuator_id, version)
);
CREATE INDEX IF NOT EXISTS estimates_sensor_zeros ON estimates (actuator_id, json_extract(result, '$.window.flight_id'))
    WHERE json_extract(result, '$.window.sensor_zero') IS NOT NULL;
CREATE INDEX IF NOT EXISTS estimates_inertia_reads ON estimates (actuator_id, id)
    WHERE json_extract(result, '$.window.inertia_read') IS NOT NULL;
"""  # the last two: what ``readings`` looks up before every estimate, found without reading the history


class ConflictError(Exception):
    """A window posted under a stored (actuator_id, window_id) with other content: another window."""

    def __init__(self, stored: Stored, digest: str) -> None:
        super().__init__(
            f"window_id {stored.window_id!r} of actuator {stored.actuator_id!r} was stored at {stored.stored_at} "
            f"from other content (SHA-256 {str(stored.window.content_sha256)[:12]}…, this body's {digest[:12]}…): "
            "give a new window its own window_id"
        )
        self.stored = stored


class StorageError(Exception):
    """The history file cannot be used; ``path`` names it."""

    def __init__(self, path: Path, reason: str) -> None:
        super().__init__(f"{path}: {reason}")
        self.path = path
        self.reason = reason


def _private_file(path: Path) -> None:
    """Create ``path`` 0600, or make an existing file (and its WAL and shared-memory files) 0600 again, with a
    warning: another user of the machine could read or change an actuator's history."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists():
        os.close(os.open(path, os.O_CREAT | os.O_WRONLY, 0o600))
        return
    for part in (path, path.with_name(path.name + "-wal"), path.with_name(path.name + "-shm")):
        if part.exists() and part.stat().st_mode & 0o077:
            log.warning("%s was readable by others (mode %o): made private (0600)", part, part.stat().st_mode & 0o777)
            part.chmod(0o600)


class EstimateStore:
    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._lock = threading.Lock()  # one writer at a time; WAL lets readers proceed
        try:
            _private_file(self.path)
            self._connection = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None)
            verdict = self._connection.execute("PRAGMA quick_check").fetchone()[0]
            if verdict != "ok":
                raise StorageError(self.path, f"fails SQLite's integrity check ({verdict})")
            self._connection.execute("PRAGMA journal_mode=WAL")
            self._connection.execute("PRAGMA synchronous=FULL")
            self._migrate()
        except sqlite3.DatabaseError as exc:
            raise StorageError(self.path, f"is not a usable SQLite database ({exc})") from None
        except OSError as exc:
            raise StorageError(self.path, f"cannot be opened ({exc.strerror})") from None

    def _migrate(self) -> None:
        tables = {r[0] for r in self._connection.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        keyed = "estimates" in tables and any(
            "UNIQUE" in (sql or "")
            for (sql,) in self._connection.execute(
                "SELECT sql FROM sqlite_master WHERE type = 'table' AND name = 'estimates'"
            )
        )
        with self._lock:
            self._connection.execute("BEGIN IMMEDIATE")
            if "estimates" in tables and not keyed:
                self._connection.execute("ALTER TABLE estimates RENAME TO estimates_v1")
                self._connection.execute("DROP INDEX IF EXISTS estimates_by_actuator")
                self._connection.execute("DROP INDEX IF EXISTS estimates_by_window")
            for statement in filter(str.strip, SCHEMA_SQL.split(";")):
                self._connection.execute(statement)
            columns = {row[1] for row in self._connection.execute("PRAGMA table_info(estimates)")}
            if "content_sha256" not in columns:  # a history from before digests: its rows keep NULL (unknown)
                self._connection.execute("ALTER TABLE estimates ADD COLUMN content_sha256 TEXT")
            if "estimates" in tables and not keyed:
                self._connection.execute(
                    "INSERT OR IGNORE INTO estimates (actuator_id, window_id, stored_at, result) "
                    "SELECT actuator_id, window_id, stored_at, result FROM estimates_v1 ORDER BY id"
                )
            self._connection.execute("COMMIT")

    def close(self) -> None:
        with self._lock:
            self._connection.close()

    def healthy(self) -> tuple[bool, str]:
        try:
            with self._lock:
                self._connection.execute("SELECT count(*) FROM estimates").fetchone()
            return True, "ok"
        except sqlite3.Error as exc:
            return False, f"{self.path}: {exc}"

    def add(self, result: Estimate) -> Stored:
        """Store one result; if its (actuator_id, window_id) is stored already from the same content, that row,
        marked as a replay (ConflictError if from other content)."""
        stored_at = dt.datetime.now(dt.UTC).isoformat(timespec="milliseconds")
        document = result.model_dump_json(by_alias=True)
        digest = result.window.content_sha256
        with self._lock:
            cursor = self._connection.execute(
                "INSERT OR IGNORE INTO estimates (actuator_id, window_id, stored_at, result, content_sha256) "
                "VALUES (?, ?, ?, ?, ?)",
                (result.actuator_id, result.window_id, stored_at, document, digest),
            )
        if cursor.rowcount == 0:
            found = self.get(result.actuator_id, result.window_id, digest)
            assert found is not None
            return found
        return Stored(**json.loads(document), id=cursor.lastrowid, stored_at=stored_at)

    def get(self, actuator_id: str, window_id: str, digest: str | None = None) -> Stored | None:
        """The stored answer for this window, marked as a replay, or None; ConflictError where it was stored
        from content other than ``digest`` (a row stored before digests is taken for the same window)."""
        with self._lock:
            row = self._connection.execute(
                "SELECT id, stored_at, result, content_sha256 FROM estimates WHERE actuator_id = ? AND window_id = ?",
                (actuator_id, window_id),
            ).fetchone()
        if row is None:
            return None
        stored = Stored(**json.loads(row[2]), id=row[0], stored_at=row[1], replay=True)
        if digest is not None and row[3] is not None and row[3] != digest:
            raise ConflictError(stored, digest)
        return stored

    def put_actuator(self, actuator_id: str, document: Actuator) -> StoredActuator:
        """Store ``document`` as the actuator's next version (the latest version itself where it is the same
        document: a PUT repeated stores nothing new). Earlier versions stay, as do the estimates read with them."""
        text = document.model_dump_json(by_alias=True)
        with self._lock:
            self._connection.execute("BEGIN IMMEDIATE")
            try:
                latest = self._connection.execute(
                    "SELECT version, stored_at, document FROM actuators WHERE actuator_id = ? "
                    "ORDER BY version DESC LIMIT 1",
                    (actuator_id,),
                ).fetchone()
                if latest is not None and latest[2] == text:
                    self._connection.execute("COMMIT")
                    return StoredActuator(
                        actuator_id=actuator_id, version=latest[0], stored_at=latest[1], document=document
                    )
                version = 1 if latest is None else latest[0] + 1
                stored_at = dt.datetime.now(dt.UTC).isoformat(timespec="milliseconds")
                self._connection.execute(
                    "INSERT INTO actuators (actuator_id, version, stored_at, document) VALUES (?, ?, ?, ?)",
                    (actuator_id, version, stored_at, text),
                )
                self._connection.execute("COMMIT")
            except BaseException:
                self._connection.execute("ROLLBACK")
                raise
        return StoredActuator(actuator_id=actuator_id, version=version, stored_at=stored_at, document=document)

    def get_actuator(self, actuator_id: str) -> StoredActuator | None:
        """The actuator's latest stored document, or None where it has none."""
        with self._lock:
            row = self._connection.execute(
                "SELECT version, stored_at, document FROM actuators WHERE actuator_id = ? ORDER BY version DESC "
                "LIMIT 1",
                (actuator_id,),
            ).fetchone()
        if row is None:
            return None
        return StoredActuator(
            actuator_id=actuator_id, version=row[0], stored_at=row[1], document=Actuator.model_validate_json(row[2])
        )

    def add_calibration(self, actuator_id: str, report: CalibrationReport) -> None:
        """Keep a calibration report of the actuator's windows (the operator's page lists them)."""
        stored_at = dt.datetime.now(dt.UTC).isoformat(timespec="milliseconds")
        with self._lock:
            self._connection.execute(
                "INSERT INTO calibrations (actuator_id, stored_at, report) VALUES (?, ?, ?)",
                (actuator_id, stored_at, report.model_dump_json(by_alias=True)),
            )

    def calibrations(self, actuator_id: str) -> list[tuple[str, CalibrationReport]]:
        """The actuator's calibration reports with when each was stored, latest first."""
        with self._lock:
            rows = self._connection.execute(
                "SELECT stored_at, report FROM calibrations WHERE actuator_id = ? ORDER BY id DESC", (actuator_id,)
            ).fetchall()
        return [(stored_at, CalibrationReport.model_validate_json(report)) for stored_at, report in rows]

    def actuator_ids(self) -> list[str]:
        """Every actuator with a stored estimate or document, in name order."""
        with self._lock:
            rows = self._connection.execute(
                "SELECT actuator_id FROM estimates UNION SELECT actuator_id FROM actuators ORDER BY actuator_id"
            ).fetchall()
        return [row[0] for row in rows]

    def readings(self, actuator_id: str, flight_id: str | None) -> HistoryReadings:
        """What the stored windows of this actuator lend a window of ``flight_id`` (``ema.estimate.history.lent``)."""
        zeros = [] if flight_id is None else self._column(actuator_id, "sensor_zero", flight_id)
        inertias = self._column(actuator_id, "inertia_read")
        return lent(
            (SensorZero.model_validate_json(zero) for zero in zeros),
            [InertiaReading.model_validate_json(reading) for reading in inertias],
        )

    def _column(self, actuator_id: str, name: str, flight_id: str | None = None) -> list[str]:
        """The non-null ``window.<name>`` of the actuator's stored results (of ``flight_id``'s), oldest first."""
        field = f"json_extract(result, '$.window.{name}')"  # a field of ours, never a caller's string
        query = f"SELECT {field} FROM estimates WHERE actuator_id = ? AND {field} IS NOT NULL"
        arguments = [actuator_id]
        if flight_id is not None:
            query += " AND json_extract(result, '$.window.flight_id') = ?"
            arguments.append(flight_id)
        with self._lock:
            return [row[0] for row in self._connection.execute(query + " ORDER BY id", arguments).fetchall()]

    def history(self, actuator_id: str) -> tuple[list[Stored], list[dict[str, Any]]]:
        """Every stored result of one actuator, oldest first; rows of an earlier format apart, as stored."""
        with self._lock:
            rows = self._connection.execute(
                "SELECT id, stored_at, result FROM estimates WHERE actuator_id = ? ORDER BY id", (actuator_id,)
            ).fetchall()
        current, legacy = [], []
        for row_id, stored_at, result in rows:
            document = json.loads(result)
            try:
                current.append(Stored(**document, id=row_id, stored_at=stored_at))
            except ValidationError:
                legacy.append({**document, "id": row_id, "stored_at": stored_at})
        return current, legacy
