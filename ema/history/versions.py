"""An actuator's documents in the history, versioned 1, 2, …: two replicas allocating a version at once collide
on the key, and the later one takes the next; a document stored again as it is is its latest version."""

from __future__ import annotations

import random
import time
from collections.abc import Sequence
from typing import Any

import sqlalchemy as sa

from ema.history.connection import SqlStore, now
from ema.history.refusals import VersionContentionError
from ema.history.tables import actuators
from ema.model.actuator import ActuatorDocument, actuator_from_json
from ema.prognosis.documents import StoredActuator

VERSION_ATTEMPTS = 20  # replicas racing for an actuator's next document version
BACKOFF_S = 0.005  # the first retry's longest wait; it doubles with each attempt


class VersionedDocuments(SqlStore):
    """The actuator documents of a history on a SQL database (``ema.history.sql.SqlHistory`` is one)."""

    def put_actuator(self, actuator_id: str, document: ActuatorDocument) -> StoredActuator:
        """Store ``document`` as the actuator's next version (the latest version itself where it is the same
        document: a PUT repeated stores nothing new). Earlier versions stay, as do the estimates read with them.

        Writers of one actuator's documents take turns (PostgreSQL: a lock of that actuator for the transaction;
        SQLite writes one at a time), so replicas racing for a version wait rather than fail; a version taken
        meanwhile all the same is retried after a random backoff, and ``VersionContentionError`` (409) only past
        ``VERSION_ATTEMPTS``."""
        text = document.model_dump_json(by_alias=True)
        for attempt in range(VERSION_ATTEMPTS):
            try:
                with self._writing() as connection:
                    self._take_turn(connection, actuator_id)
                    latest = self._latest_document(actuator_id, connection)
                    if latest is not None and latest.document == text:
                        return StoredActuator(
                            actuator_id=actuator_id,
                            version=latest.version,
                            stored_at=latest.stored_at,
                            document=document,
                        )
                    version, stored_at = 1 if latest is None else latest.version + 1, now()
                    row = {"actuator_id": actuator_id, "version": version, "stored_at": stored_at, "document": text}
                    connection.execute(actuators.insert().values(**row))
            except sa.exc.IntegrityError:
                time.sleep(random.uniform(0.0, BACKOFF_S * 2 ** min(attempt, 6)))  # another writer took it: again
                continue
            return StoredActuator(actuator_id=actuator_id, version=version, stored_at=stored_at, document=document)
        raise VersionContentionError(actuator_id, VERSION_ATTEMPTS)

    def _take_turn(self, connection: sa.Connection, actuator_id: str) -> None:
        """On PostgreSQL, hold this actuator's document lock until the transaction ends."""
        if self.engine.dialect.name == "postgresql":
            key = {"key": f"ema-actuator:{actuator_id}"}
            connection.execute(sa.text("SELECT pg_advisory_xact_lock(hashtextextended(:key, 0))"), key)

    def _latest_document(self, actuator_id: str, connection: sa.Connection | None = None) -> Any:
        query = (
            sa.select(actuators.c.version, actuators.c.stored_at, actuators.c.document)
            .where(actuators.c.actuator_id == actuator_id)
            .order_by(actuators.c.version.desc())
            .limit(1)
        )
        if connection is not None:
            return connection.execute(query).first()
        with self._reading() as reading:
            return reading.execute(query).first()

    def get_actuator(self, actuator_id: str) -> StoredActuator | None:
        """The actuator's latest stored document, or None where it has none."""
        row = self._latest_document(actuator_id)
        if row is None:
            return None
        document = actuator_from_json(row.document)
        return StoredActuator(actuator_id=actuator_id, version=row.version, stored_at=row.stored_at, document=document)

    def latest_documents(self, actuator_ids: Sequence[str]) -> dict[str, StoredActuator]:
        """The latest document of each of ``actuator_ids`` that has one (one query)."""
        newest = (
            sa.select(actuators.c.actuator_id, sa.func.max(actuators.c.version).label("version"))
            .where(actuators.c.actuator_id.in_(actuator_ids))
            .group_by(actuators.c.actuator_id)
            .subquery()
        )
        query = sa.select(actuators).join(
            newest, sa.and_(actuators.c.actuator_id == newest.c.actuator_id, actuators.c.version == newest.c.version)
        )
        with self._reading() as connection:
            rows = connection.execute(query).all()
        return {
            row.actuator_id: StoredActuator(
                actuator_id=row.actuator_id,
                version=row.version,
                stored_at=row.stored_at,
                document=actuator_from_json(row.document),
            )
            for row in rows
        }
