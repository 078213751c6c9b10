"""The history's tables, defined once for every database (SQLAlchemy Core); migrations build them.

What a lookup before every estimate needs is a column of its own, extracted when the row is written
(``flight_id``, and what the window lends its flight's and its actuator's other windows: ``lent_to_flight``,
``lent_to_actuator``, each its kind's JSON), so that no query parses stored JSON.
"""

from __future__ import annotations

from sqlalchemy import Column, Float, Index, Integer, MetaData, PrimaryKeyConstraint, Table, Text, UniqueConstraint

metadata = MetaData()


def _required(name: str, kind: type[Integer] | type[Text] = Text) -> Column:
    return Column(name, kind, nullable=False)


def _per_actuator(name: str, *columns: Column | UniqueConstraint) -> Table:
    """A table of rows appended per actuator: an id in the order they were stored, the actuator_id, ``columns``;
    indexed to be read by actuator in that order."""
    table = Table(
        name,
        metadata,
        Column("id", Integer, primary_key=True, autoincrement=True),
        _required("actuator_id"),
        *columns,
        sqlite_autoincrement=True,
    )
    Index(f"{name}_by_actuator", table.c.actuator_id, table.c.id)
    return table


estimates = _per_actuator(
    "estimates",
    _required("window_id"),
    _required("stored_at"),
    _required("result"),
    Column("content_sha256", Text),
    Column("flight_id", Text),
    Column("lent_to_flight", Text),
    Column("lent_to_actuator", Text),
    UniqueConstraint("actuator_id", "window_id", name="estimates_actuator_window"),
)
Index("estimates_by_flight", estimates.c.actuator_id, estimates.c.flight_id)  # what a flight's windows lend
calibrations = _per_actuator("calibrations", _required("stored_at"), _required("report"))
withdrawals = _per_actuator(
    "withdrawals",
    _required("window_id"),
    _required("withdrawn_at"),
    _required("reason"),
    _required("stored_at"),
    Column("content_sha256", Text),
    _required("result"),
)
actuators = Table(
    "actuators",
    metadata,
    _required("actuator_id"),
    _required("version", Integer),
    _required("stored_at"),
    _required("document"),
    PrimaryKeyConstraint("actuator_id", "version", name="actuators_version"),
)
summaries = Table(
    "summaries",
    metadata,
    Column("actuator_id", Text, primary_key=True),
    _required("state"),
    _required("urgency", Integer),
    Column("soonest", Float),
    _required("row"),
)
