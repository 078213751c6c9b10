"""Bring a history's tables to the current revision (Alembic), whatever revision it was left at.

A history written before migrations were kept (an SQLite file of round 1 to 3) is first brought to
round 3's tables the way round 3 did it: a table without the (actuator_id, window_id) key is kept as
``estimates_v1`` and its rows copied once each, oldest first. It is then stamped as round 3 and
migrated like any other. Replicas that start together on one PostgreSQL migrate one at a time.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import sqlalchemy as sa
from alembic import command
from alembic.config import Config

MIGRATIONS = Path(__file__).resolve().parent / "migrations"
FIRST_REVISION = "r3"
LOCK_KEY = 0x454D41  # "EMA": the advisory lock replicas take to migrate one at a time


def _config(connection: sa.Connection) -> Config:
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    config.attributes["connection"] = connection
    return config


class ForeignTablesError(Exception):
    """The database holds tables of another program's under ema's names."""


def upgrade(engine: sa.Engine) -> None:
    """Migrate ``engine``'s history to the latest revision (a new history is created)."""
    with engine.connect() as connection:
        if engine.dialect.name == "postgresql":
            connection.execute(sa.text("SELECT pg_advisory_lock(:key)"), {"key": LOCK_KEY})
            connection.commit()
        try:
            tables = set(sa.inspect(connection).get_table_names())
            if "alembic_version" not in tables and "estimates" in tables:
                _ours_from_round_three(connection)
                _round_three(connection, tables)
                connection.commit()
                command.stamp(_config(connection), FIRST_REVISION)
                connection.commit()
            command.upgrade(_config(connection), "head")
            connection.commit()
        finally:
            if engine.dialect.name == "postgresql":
                connection.execute(sa.text("SELECT pg_advisory_unlock(:key)"), {"key": LOCK_KEY})
                connection.commit()


def _ours_from_round_three(connection: sa.Connection) -> None:
    """A table ``estimates`` without migrations is an SQLite history of ema's from before them, else another
    program's: refused (``ForeignTablesError``), never altered. PostgreSQL histories were migrated from the start."""
    columns = {column["name"] for column in sa.inspect(connection).get_columns("estimates")}
    if connection.dialect.name != "sqlite" or not {"actuator_id", "window_id", "result"} <= columns:
        connection.rollback()
        raise ForeignTablesError(
            "holds a table 'estimates' that is not an ema history's: give ema a database of its own"
        )


def _round_three(connection: sa.Connection, tables: set[str]) -> None:
    """An SQLite history from before migrations, in round 3's tables (round 1's unkeyed rows copied once)."""
    keyed = any(
        "UNIQUE" in (sql or "")
        for (sql,) in connection.exec_driver_sql(
            "SELECT sql FROM sqlite_master WHERE type = 'table' AND name = 'estimates'"
        )
    )
    if not keyed:
        connection.exec_driver_sql("ALTER TABLE estimates RENAME TO estimates_v1")
        for index in ("estimates_by_actuator", "estimates_by_window"):
            connection.exec_driver_sql(f"DROP INDEX IF EXISTS {index}")
    connection.exec_driver_sql(
        "CREATE TABLE IF NOT EXISTS estimates (id INTEGER PRIMARY KEY AUTOINCREMENT, actuator_id TEXT NOT NULL, "
        "window_id TEXT NOT NULL, stored_at TEXT NOT NULL, result TEXT NOT NULL, content_sha256 TEXT, "
        "UNIQUE (actuator_id, window_id))"
    )
    connection.exec_driver_sql("CREATE INDEX IF NOT EXISTS estimates_by_actuator ON estimates (actuator_id, id)")
    columns = {row[1] for row in connection.exec_driver_sql("PRAGMA table_info(estimates)")}
    if "content_sha256" not in columns:  # a history from before digests: its rows keep NULL (unknown)
        connection.exec_driver_sql("ALTER TABLE estimates ADD COLUMN content_sha256 TEXT")
    if not keyed:
        connection.exec_driver_sql(
            "INSERT OR IGNORE INTO estimates (actuator_id, window_id, stored_at, result) "
            "SELECT actuator_id, window_id, stored_at, result FROM estimates_v1 ORDER BY id"
        )
    if "calibrations" not in tables:
        connection.exec_driver_sql(
            "CREATE TABLE calibrations (id INTEGER PRIMARY KEY AUTOINCREMENT, actuator_id TEXT NOT NULL, "
            "stored_at TEXT NOT NULL, report TEXT NOT NULL)"
        )
        connection.exec_driver_sql("CREATE INDEX calibrations_by_actuator ON calibrations (actuator_id, id)")
    if "actuators" not in tables:
        connection.exec_driver_sql(
            "CREATE TABLE actuators (actuator_id TEXT NOT NULL, version INTEGER NOT NULL, stored_at TEXT NOT NULL, "
            "document TEXT NOT NULL, PRIMARY KEY (actuator_id, version))"
        )


@contextlib.contextmanager
def opening(engine: sa.Engine, location: object, unusable: str) -> Iterator[None]:
    """The steps that open a history (its tables checked, upgraded): where one fails, the engine is let go and a
    StorageError names ``location``, another program's tables as such, a database error as ``unusable`` with
    its reason's first line."""
    from ema.history.refusals import StorageError

    try:
        yield
    except ForeignTablesError as exc:
        engine.dispose()
        raise StorageError(location, str(exc)) from None
    except sa.exc.SQLAlchemyError as exc:
        engine.dispose()
        reason = str(getattr(exc, "orig", exc)).strip().splitlines()[0]
        raise StorageError(location, f"{unusable} ({reason})") from None
