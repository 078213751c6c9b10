"""The history of every answered estimate: SQLite in WAL mode, committed before the answer leaves.

``synchronous=FULL`` makes a commit durable across a kill -9 of the server (and a power loss),
so an estimate a client has received is never lost. Rows are only ever inserted: re-posting a
window adds a row rather than overwriting what was answered before.
"""

from __future__ import annotations

import datetime as dt
import json
import sqlite3
import threading
from pathlib import Path
from typing import Any

import numpy as np

SCHEMA_SQL = """
CREATE TABLE IF NOT EXISTS estimates (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    actuator_id TEXT NOT NULL,
    window_id TEXT NOT NULL,
    stored_at TEXT NOT NULL,
    result TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS estimates_by_actuator ON estimates (actuator_id, id);
CREATE INDEX IF NOT EXISTS estimates_by_window ON estimates (actuator_id, window_id);
"""
TRENDED = ("FDJ", "eta_O", "eta_A")


class EstimateStore:
    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = threading.Lock()  # one writer at a time; WAL lets readers proceed
        self._connection = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None)
        self._connection.execute("PRAGMA journal_mode=WAL")
        self._connection.execute("PRAGMA synchronous=FULL")
        self._connection.executescript(SCHEMA_SQL)

    def close(self) -> None:
        with self._lock:
            self._connection.close()

    def add(self, result: dict[str, Any]) -> dict[str, Any]:
        """Store one ``ema-estimate/1`` result; returns it with its ``id`` and ``stored_at``."""
        stored_at = dt.datetime.now(dt.UTC).isoformat(timespec="milliseconds")
        with self._lock:
            cursor = self._connection.execute(
                "INSERT INTO estimates (actuator_id, window_id, stored_at, result) VALUES (?, ?, ?, ?)",
                (result["actuator_id"], result["window_id"], stored_at, json.dumps(result)),
            )
        return {**result, "id": cursor.lastrowid, "stored_at": stored_at}

    def history(self, actuator_id: str) -> list[dict[str, Any]]:
        """Every stored result of one actuator, oldest first."""
        with self._lock:
            rows = self._connection.execute(
                "SELECT id, stored_at, result FROM estimates WHERE actuator_id = ? ORDER BY id", (actuator_id,)
            ).fetchall()
        return [{**json.loads(result), "id": row_id, "stored_at": stored_at} for row_id, stored_at, result in rows]


def trend(history: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per parameter: first, last, and the least-squares slope per day over the stored time.

    The slope is what a remaining-useful-life estimate extrapolates; it needs two points.
    """
    if not history:
        return {}
    times = np.array([dt.datetime.fromisoformat(h["stored_at"]).timestamp() for h in history]) / 86_400.0
    out = {}
    for name in TRENDED:
        values = np.array([h["estimates"][name]["value"] for h in history])
        slope = None
        if len(values) >= 2 and np.ptp(times) > 0:
            slope = float(np.polyfit(times - times[0], values, 1)[0])
        out[name] = {
            "n": len(values),
            "first": float(values[0]),
            "last": float(values[-1]),
            "slope_per_day": slope,
            "drift_pct_last": float(history[-1]["estimates"][name]["drift_pct"]),
        }
    return out
