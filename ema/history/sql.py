"""The history on a SQL database (SQLAlchemy Core): one implementation for SQLite and PostgreSQL.

- One row per (actuator_id, window_id), inserted with "on conflict do nothing": the same window
  stored twice, by one process or by replicas racing, is one row, and both get that row's answer.
  Another body under a stored key is a :class:`ConflictError`.
- Committed before the answer leaves (SQLite: ``synchronous=FULL``; PostgreSQL commits durably).
- Actuator documents are versioned 1, 2, … (``ema.history.versions``).
- A withdrawn window leaves the history but not the database: its row moves to ``withdrawals``, and its key is
  retired: posted again, it is refused with its withdrawal (``WithdrawnError``), never estimated anew.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import sqlalchemy as sa
from pydantic import ValidationError

from ema.calibration.documents import CALIBRATION_REPORT, CalibrationReport
from ema.estimate.documents import Estimate
from ema.history.connection import now
from ema.history.refusals import ConflictError, WithdrawnError
from ema.history.tables import actuators, calibrations, estimates, summaries, withdrawals
from ema.history.versions import VersionedDocuments
from ema.kinds import Borrowed, lent_by
from ema.prognosis.documents import Stored, Withdrawal


class SqlHistory(VersionedDocuments):
    """An actuator history on ``engine``; ``probe()`` raises StorageError where a write cannot be taken now."""

    def add(self, result: Estimate) -> Stored:
        """Store one result; where its (actuator_id, window_id) is stored already from the same content, that row,
        marked as a replay (ConflictError where from other content; WithdrawnError where it was withdrawn)."""
        stored_at, document, info = now(), result.model_dump_json(by_alias=True), result.window
        lent = lent_by(info)  # kept in their own columns: what the actuator's other windows borrow
        row = {
            "actuator_id": result.actuator_id,
            "window_id": result.window_id,
            "stored_at": stored_at,
            "result": document,
            "content_sha256": info.content_sha256,
            "flight_id": info.flight_id,
            "lent_to_flight": lent.to_flight,
            "lent_to_actuator": lent.to_actuator,
        }
        statement = self._insert(estimates).values(**row).on_conflict_do_nothing().returning(estimates.c.id)
        with self._writing() as connection:
            self._refuse_withdrawn(connection, result.actuator_id, result.window_id)
            new_id = connection.execute(statement).scalar_one_or_none()
        if new_id is None:
            found = self.get(result.actuator_id, result.window_id, info.content_sha256)
            assert found is not None
            return found
        return Stored(**json.loads(document), id=new_id, stored_at=stored_at)

    def get(self, actuator_id: str, window_id: str, digest: str | None = None) -> Stored | None:
        """The stored answer for this window, marked as a replay, or None; ConflictError where it was stored
        from content other than ``digest`` (a row stored before digests is taken for the same window), WithdrawnError
        where it was withdrawn."""
        query = sa.select(estimates.c.id, estimates.c.stored_at, estimates.c.result, estimates.c.content_sha256)
        with self._reading() as connection:
            row = connection.execute(
                query.where(estimates.c.actuator_id == actuator_id, estimates.c.window_id == window_id)
            ).first()
            if row is None:
                self._refuse_withdrawn(connection, actuator_id, window_id)
                return None
        stored = Stored(**json.loads(row.result), id=row.id, stored_at=row.stored_at, replay=True)
        if digest is not None and row.content_sha256 is not None and row.content_sha256 != digest:
            raise ConflictError(stored, digest)
        return stored

    def _refuse_withdrawn(self, connection: sa.Connection, actuator_id: str, window_id: str) -> None:
        """WithdrawnError where an operator withdrew this window: its key stays retired."""
        columns = [withdrawals.c[name] for name in Withdrawal.model_fields if name != "actuator_id"]
        found = connection.execute(
            sa.select(*columns)
            .where(withdrawals.c.actuator_id == actuator_id, withdrawals.c.window_id == window_id)
            .order_by(withdrawals.c.id.desc())
        ).first()
        if found is not None:
            raise WithdrawnError(Withdrawal(actuator_id=actuator_id, **found._mapping))

    def withdraw(self, actuator_id: str, window_id: str, reason: str) -> Withdrawal | None:
        """Take a stored window out of the history, keeping it and why in ``withdrawals``; None where none is
        stored under that key."""
        withdrawn_at = now()
        with self._writing() as connection:
            row = connection.execute(
                sa.delete(estimates)
                .where(estimates.c.actuator_id == actuator_id, estimates.c.window_id == window_id)
                .returning(estimates.c.stored_at, estimates.c.content_sha256, estimates.c.result)
            ).first()
            if row is None:
                return None
            withdrawal = Withdrawal(
                actuator_id=actuator_id,
                window_id=window_id,
                withdrawn_at=withdrawn_at,
                reason=reason,
                stored_at=row.stored_at,
                content_sha256=row.content_sha256,
            )
            connection.execute(withdrawals.insert().values(**withdrawal.model_dump(), result=row.result))
        return withdrawal

    def withdrawals(self, actuator_id: str) -> list[Withdrawal]:
        """The actuator's withdrawn windows, oldest withdrawal first."""
        columns = [withdrawals.c[name] for name in Withdrawal.model_fields if name != "actuator_id"]
        with self._reading() as connection:
            rows = connection.execute(
                sa.select(*columns).where(withdrawals.c.actuator_id == actuator_id).order_by(withdrawals.c.id)
            ).all()
        return [Withdrawal(actuator_id=actuator_id, **row._mapping) for row in rows]

    def add_calibration(self, actuator_id: str, report: CalibrationReport) -> None:
        """Keep a calibration report of the actuator's windows (the operator's page lists them)."""
        report_text = report.model_dump_json(by_alias=True)
        with self._writing() as connection:
            connection.execute(
                calibrations.insert().values(actuator_id=actuator_id, stored_at=now(), report=report_text)
            )

    def calibrations(self, actuator_id: str) -> list[tuple[str, CalibrationReport]]:
        """The actuator's calibration reports with when each was stored, latest first."""
        with self._reading() as connection:
            rows = connection.execute(
                sa.select(calibrations.c.stored_at, calibrations.c.report)
                .where(calibrations.c.actuator_id == actuator_id)
                .order_by(calibrations.c.id.desc())
            ).all()
        return [(row.stored_at, CALIBRATION_REPORT.validate_json(row.report)) for row in rows]

    def actuator_ids(self) -> list[str]:
        """Every actuator with a stored estimate, document or withdrawn window, in name order."""
        query = sa.union(
            sa.select(estimates.c.actuator_id), sa.select(actuators.c.actuator_id), sa.select(withdrawals.c.actuator_id)
        )
        with self._reading() as connection:
            return sorted(row[0] for row in connection.execute(query))

    def versions(self) -> dict[str, tuple[int, int, int]]:
        """Per actuator: (stored windows, the latest window's row id, its latest document version; 0 for none),
        which change exactly when its prognosis may."""
        counted = sa.select(estimates.c.actuator_id, sa.func.count(), sa.func.max(estimates.c.id)).group_by(
            estimates.c.actuator_id
        )
        documents = sa.select(actuators.c.actuator_id, sa.func.max(actuators.c.version)).group_by(
            actuators.c.actuator_id
        )
        with self._reading() as connection:
            found = {row[0]: (int(row[1]), int(row[2]), 0) for row in connection.execute(counted)}
            for actuator_id, version in connection.execute(documents):
                count, last, _ = found.get(actuator_id, (0, 0, 0))
                found[actuator_id] = (count, last, int(version))
        return found

    def latest(self, actuator_ids: Sequence[str]) -> dict[str, Stored]:
        """The latest stored estimate of each of ``actuator_ids`` that has one (one query)."""
        last = (
            sa.select(sa.func.max(estimates.c.id))
            .where(estimates.c.actuator_id.in_(actuator_ids))
            .group_by(estimates.c.actuator_id)
        )
        query = sa.select(estimates.c.id, estimates.c.stored_at, estimates.c.result).where(estimates.c.id.in_(last))
        with self._reading() as connection:
            rows = connection.execute(query).all()
        found = {}
        for row in rows:
            try:
                stored = Stored(**json.loads(row.result), id=row.id, stored_at=row.stored_at)
            except ValidationError:
                continue  # an earlier format's row: no line of the view is built from it
            found[stored.actuator_id] = stored
        return found

    def lent_to(self, actuator_id: str, flight_id: str | None) -> Borrowed:
        """What the stored windows of this actuator lent a window of ``flight_id``, oldest first: those of its flight
        to their flight's windows, and every one to the actuator's (its kind reads them: ``other_windows_lent``)."""
        mine = estimates.c.actuator_id == actuator_id
        with self._reading() as connection:
            from_flight: Sequence[str] = []
            if flight_id is not None:
                from_flight = (
                    connection.execute(
                        sa.select(estimates.c.lent_to_flight)
                        .where(mine, estimates.c.flight_id == flight_id, estimates.c.lent_to_flight.is_not(None))
                        .order_by(estimates.c.id)
                    )
                    .scalars()
                    .all()
                )
            from_actuator = (
                connection.execute(
                    sa.select(estimates.c.lent_to_actuator)
                    .where(mine, estimates.c.lent_to_actuator.is_not(None))
                    .order_by(estimates.c.id)
                )
                .scalars()
                .all()
            )
            return Borrowed(from_flight=tuple(from_flight), from_actuator=tuple(from_actuator))

    def history(self, actuator_id: str) -> tuple[list[Stored], list[dict[str, Any]]]:
        """Every stored result of one actuator, oldest first; rows of an earlier format apart, as stored."""
        with self._reading() as connection:
            rows = connection.execute(
                sa.select(estimates.c.id, estimates.c.stored_at, estimates.c.result)
                .where(estimates.c.actuator_id == actuator_id)
                .order_by(estimates.c.id)
            ).all()
        current, legacy = [], []
        for row_id, stored_at, result in rows:
            document = json.loads(result)
            try:
                current.append(Stored(**document, id=row_id, stored_at=stored_at))
            except ValidationError:
                legacy.append({**document, "id": row_id, "stored_at": stored_at})
        return current, legacy

    def summaries(self) -> dict[str, tuple[str, str]]:
        """Every kept fleet-view summary: actuator -> (the state it was computed at, its row as JSON)."""
        with self._reading() as connection:
            rows = connection.execute(sa.select(summaries.c.actuator_id, summaries.c.state, summaries.c.row))
            return {row.actuator_id: (row.state, row.row) for row in rows}

    def put_summary(self, actuator_id: str, state: str, urgency: int, soonest: float | None, row: str) -> None:
        """Keep the fleet view's summary of an actuator, computed at ``state`` (replacing the one kept)."""
        values = {"state": state, "urgency": urgency, "soonest": soonest, "row": row}
        statement = self._insert(summaries).values(actuator_id=actuator_id, **values)
        statement = statement.on_conflict_do_update(index_elements=[summaries.c.actuator_id], set_=values)
        with self._writing() as connection:
            connection.execute(statement)
