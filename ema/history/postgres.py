"""PostgreSQL as the history: a ground station's, shared by every service replica and the fleet runner.

Replicas are one service because the database decides every race: a window stored twice is one row
(its key), a document version allocated twice is one (its key), and whatever was answered 200 was
committed first. ``probe`` asks the server for a writable session before any pipeline runs.
"""

from __future__ import annotations

import sqlalchemy as sa

from ema.history.refusals import StorageError
from ema.history.schema import opening, upgrade
from ema.history.sql import SqlHistory


def shown(address: sa.URL) -> str:
    """The address as logs and errors show it: never its password."""
    return address.render_as_string(hide_password=True)


def open_postgres(address: str) -> SqlHistory:
    """The history in the PostgreSQL database at ``address`` (``postgresql://user@host:port/db``), migrated."""
    try:
        url = sa.make_url(address).set(drivername="postgresql+psycopg")
    except sa.exc.ArgumentError as exc:
        raise StorageError(address.split("@")[-1], f"is not a database address ({exc})") from None
    location = shown(url)
    engine = sa.create_engine(url, pool_pre_ping=True, pool_size=8, max_overflow=8)
    with opening(engine, location, "cannot be opened"):
        upgrade(engine)

    def probe() -> None:
        try:
            with engine.connect() as connection:
                if connection.exec_driver_sql("SHOW transaction_read_only").scalar() == "on":
                    raise StorageError(location, "is read-only (a standby?): the service stores every answer")
        except sa.exc.SQLAlchemyError as exc:
            reason = str(getattr(exc, "orig", exc)).strip().splitlines()[0]
            raise StorageError(location, f"does not answer ({reason})") from None

    return SqlHistory(engine, location, probe)
