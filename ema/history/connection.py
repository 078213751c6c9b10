"""A SQL database as the history's storage: transactions whose failures name the history, and a health check.

``probe`` says whether the storage can take a write now (``ema.history.sqlite``, ``ema.history.postgres``);
the service asks before any pipeline runs.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import sqlalchemy as sa
from sqlalchemy.dialects import postgresql, sqlite

from ema.history.refusals import StorageError
from ema.history.tables import actuators


def now() -> str:
    """The moment, as the history stores it: UTC, ISO 8601 to the millisecond."""
    return dt.datetime.now(dt.UTC).isoformat(timespec="milliseconds")


class SqlStore:
    """A database behind ``engine`` whose failures name the history at ``location``; ``probe()`` raises StorageError
    where a write cannot be taken now."""

    def __init__(self, engine: sa.Engine, location: str, probe: Callable[[], None]) -> None:
        self.engine = engine
        self.location = location
        self.probe = probe
        self._insert = postgresql.insert if engine.dialect.name == "postgresql" else sqlite.insert

    @contextmanager
    def _writing(self) -> Iterator[sa.Connection]:
        """A transaction that commits on leaving; a database failure becomes a StorageError naming the history."""
        try:
            with self.engine.begin() as connection:
                yield connection
        except sa.exc.IntegrityError:
            raise
        except sa.exc.SQLAlchemyError as exc:
            raise StorageError(self.location, f"cannot be written ({_reason(exc)})") from None

    @contextmanager
    def _reading(self) -> Iterator[sa.Connection]:
        try:
            with self.engine.connect() as connection:
                yield connection
        except sa.exc.SQLAlchemyError as exc:
            raise StorageError(self.location, f"cannot be read ({_reason(exc)})") from None

    def close(self) -> None:
        self.engine.dispose()

    def healthy(self) -> tuple[bool, str]:
        """(True, "ok"), or (False, what is wrong): the storage can take a write, and answers a read."""
        try:
            self.probe()
            with self._reading() as connection:
                connection.execute(sa.select(sa.func.count()).select_from(actuators)).scalar_one()
        except StorageError as exc:
            return False, str(exc)
        return True, "ok"


def _reason(exc: sa.exc.SQLAlchemyError) -> str:
    """The database's own words for a failure, without SQLAlchemy's statement dump."""
    original = getattr(exc, "orig", None)
    return str(original if original is not None else exc).splitlines()[0]
