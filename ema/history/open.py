"""``open_history``: the database setting (``--database``, ``EMA_DATABASE``) -> the history it names.

A ``postgresql://`` (or ``postgres://``) address opens PostgreSQL; anything else with a scheme is
refused naming the setting (it would otherwise become a folder named ``postgresql:``); the rest is a
path to an SQLite file.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol
from urllib.parse import urlsplit

from ema.calibration.documents import CalibrationReport
from ema.estimate.documents import Estimate
from ema.history.refusals import StorageError
from ema.kinds.base import Borrowed
from ema.model.actuator import ActuatorDocument
from ema.prognosis.documents import Stored, StoredActuator, Withdrawal

SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.-]*)://")
POSTGRES = ("postgresql", "postgres", "postgresql+psycopg")


class History(Protocol):
    """What the service, the fleet and the command line need of a history (``ema.history.sql.SqlHistory``)."""

    location: str

    def add(self, result: Estimate) -> Stored: ...
    def get(self, actuator_id: str, window_id: str, digest: str | None = None) -> Stored | None: ...
    def withdraw(self, actuator_id: str, window_id: str, reason: str) -> Withdrawal | None: ...
    def withdrawals(self, actuator_id: str) -> list[Withdrawal]: ...
    def put_actuator(self, actuator_id: str, document: ActuatorDocument) -> StoredActuator: ...
    def get_actuator(self, actuator_id: str) -> StoredActuator | None: ...
    def add_calibration(self, actuator_id: str, report: CalibrationReport) -> None: ...
    def calibrations(self, actuator_id: str) -> list[tuple[str, CalibrationReport]]: ...
    def actuator_ids(self) -> list[str]: ...
    def versions(self) -> dict[str, tuple[int, int, int]]: ...
    def latest(self, actuator_ids: Sequence[str]) -> dict[str, Stored]: ...
    def latest_documents(self, actuator_ids: Sequence[str]) -> dict[str, StoredActuator]: ...
    def lent_to(self, actuator_id: str, flight_id: str | None) -> Borrowed: ...
    def history(self, actuator_id: str) -> tuple[list[Stored], list[dict]]: ...
    def summaries(self) -> dict[str, tuple[str, str]]: ...
    def put_summary(self, actuator_id: str, state: str, urgency: int, soonest: float | None, row: str) -> None: ...
    def probe(self) -> None: ...
    def healthy(self) -> tuple[bool, str]: ...
    def close(self) -> None: ...


def is_address(setting: str | Path) -> bool:
    return SCHEME.match(str(setting)) is not None


def setting_error(setting: str) -> str | None:
    """Why ``setting`` names no history ema opens (a scheme it does not open, an address it cannot parse), or
    None: checked where the setting is read, so a malformed address is bad input, never a crash at start."""
    if not setting.strip():
        return "is empty: give a file path or a postgresql:// address"
    scheme = SCHEME.match(setting)
    if scheme is None:
        return None
    if scheme.group(1).lower() not in POSTGRES:
        return f"{scheme.group(1)}:// is no database ema opens: give a file path or a postgresql:// address"
    parts = urlsplit(setting)
    try:
        parts.port  # noqa: B018  # parsing it is the check
    except ValueError:
        port = parts.netloc.rsplit(":", 1)[-1]
        return f"{parts.hostname}:{port}: the port is not a number (postgresql://user:password@host:port/database)"
    if not parts.hostname and "host=" not in parts.query:
        return "names no host (postgresql://user:password@host:port/database)"
    return None


def open_history(setting: str | Path, min_free_bytes: int | None = None) -> History:
    """The history ``setting`` names; StorageError naming it where it cannot be opened."""
    text = str(setting)
    error = setting_error(text)
    if error is not None:
        raise StorageError(text.split("@")[-1], error)
    if is_address(text):
        from ema.history.postgres import open_postgres  # psycopg: only where PostgreSQL is asked for

        return open_postgres(text)
    from ema.history.sqlite import MIN_FREE_BYTES, open_sqlite

    return open_sqlite(Path(text), MIN_FREE_BYTES if min_free_bytes is None else min_free_bytes)
