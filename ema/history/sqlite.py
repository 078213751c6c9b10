"""An SQLite file as the history: the embedded default, private to its user, checked before it is touched.

- A file that is not an SQLite database, or one that holds another program's tables, is refused
  before anything about it changes (its mode included): nothing a user stored is lost.
- A read-only file or folder is refused at start: the service writes every answer.
- Created 0600; a file others could read is made private again, with a warning.
- WAL with ``synchronous=FULL``: a committed answer survives a kill -9 or a power loss.
- ``probe`` (before every write) checks that the file at the path is still the one opened (a
  history deleted or replaced under a running service would swallow every answer), that it is
  writable, and that the disk has room.
"""

from __future__ import annotations

import logging
import os
import shutil
import stat
from pathlib import Path
from typing import Any

import sqlalchemy as sa

from ema.history.refusals import StorageError
from ema.history.schema import opening, upgrade
from ema.history.sql import SqlHistory

log = logging.getLogger("ema.history")
SQLITE_HEADER = b"SQLite format 3\x00"
OURS = frozenset(
    {
        "estimates",
        "estimates_v1",
        "calibrations",
        "actuators",
        "withdrawals",
        "summaries",
        "alembic_version",
        "sqlite_sequence",
    }
)
MIN_FREE_BYTES = 50_000_000  # below this the disk is full for our purposes: a SQLite write may need pages


def _check_file(path: Path) -> None:
    """StorageError unless ``path`` is absent, empty, or an SQLite database we may write; nothing is changed."""
    if path.exists():
        if not path.is_file():
            raise StorageError(path, "is not a file")
        with path.open("rb") as handle:
            head = handle.read(len(SQLITE_HEADER))
        if head and head != SQLITE_HEADER:
            raise StorageError(path, "is not an SQLite database (refused, left as it is)")
        if not os.access(path, os.R_OK | os.W_OK) or not path.stat().st_mode & stat.S_IWUSR:
            raise StorageError(path, "is read-only: the service stores every answer it gives")
    folder = path.parent if path.parent.exists() else next(p for p in path.parents if p.exists())
    if not os.access(folder, os.W_OK | os.X_OK):
        raise StorageError(path, f"its folder {folder} is read-only: SQLite writes its journal beside the file")


def _check_tables(engine: sa.Engine, path: Path) -> None:
    """StorageError where the database fails SQLite's check or holds another program's tables."""
    with engine.connect() as connection:
        verdict = connection.exec_driver_sql("PRAGMA quick_check").scalar()
        if verdict != "ok":
            raise StorageError(path, f"fails SQLite's integrity check ({verdict})")
        tables = set(sa.inspect(connection).get_table_names())
    foreign = sorted(tables - OURS)
    if foreign and "estimates" not in tables:
        raise StorageError(path, f"holds another program's tables ({', '.join(foreign[:5])}): not an ema history")


def _private(path: Path) -> None:
    """Create ``path`` 0600, or make it (and its WAL and shared-memory files) 0600 again, with a warning."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists():
        os.close(os.open(path, os.O_CREAT | os.O_WRONLY, 0o600))
        return
    for part in (path, path.with_name(path.name + "-wal"), path.with_name(path.name + "-shm")):
        if part.exists() and part.stat().st_mode & 0o077:
            log.warning("%s was readable by others (mode %o): made private (0600)", part, part.stat().st_mode & 0o777)
            part.chmod(0o600)


def _pragmas(connection: Any, _: object) -> None:
    cursor = connection.cursor()
    cursor.execute("PRAGMA journal_mode=WAL")
    cursor.execute("PRAGMA synchronous=FULL")
    cursor.execute("PRAGMA busy_timeout=30000")
    cursor.close()


def open_sqlite(path: Path, min_free_bytes: int = MIN_FREE_BYTES) -> SqlHistory:
    """The history in the SQLite file ``path`` (created where absent), migrated to the current tables."""
    path = Path(path).absolute()
    _check_file(path)
    engine = sa.create_engine(f"sqlite:///{path}", connect_args={"check_same_thread": False, "timeout": 30})
    sa.event.listen(engine, "connect", _pragmas)
    try:
        with opening(engine, path, "is not a usable SQLite database"):
            if path.exists() and path.stat().st_size:
                _check_tables(engine, path)
            _private(path)
            upgrade(engine)
    except OSError as exc:
        engine.dispose()
        raise StorageError(path, f"cannot be opened ({exc.strerror})") from None
    opened = path.stat()
    return SqlHistory(engine, str(path), lambda: _probe(path, (opened.st_dev, opened.st_ino), min_free_bytes))


def _probe(path: Path, identity: tuple[int, int], min_free_bytes: int) -> None:
    """StorageError where the history at ``path`` cannot take a write now, naming why."""
    try:
        now = path.stat()
    except FileNotFoundError:
        raise StorageError(path, "was deleted under the running service: restart it to open a new history") from None
    if (now.st_dev, now.st_ino) != identity:
        raise StorageError(path, "was replaced under the running service: restart it to open the file there now")
    if not stat.S_IMODE(now.st_mode) & stat.S_IWUSR or not os.access(path, os.W_OK):
        raise StorageError(path, "became read-only: the service stores every answer it gives")
    free = shutil.disk_usage(path.parent).free
    if free < min_free_bytes:
        raise StorageError(path, f"its disk has {free / 1e6:.0f} MB free, under the {min_free_bytes / 1e6:.0f} MB kept")
