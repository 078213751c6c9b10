"""The history's tables, defined once for every database (SQLAlchemy Core); migrations build them.

What a lookup before every estimate needs is a column of its own, extracted when the row is written
(``flight_id``, ``sensor_zero``, ``inertia_read``), so that no query parses stored JSON.
"""

from __future__ import annotations

from sqlalchemy import Column, Float, Index, Integer, MetaData, PrimaryKeyConstraint, Table, Text, UniqueConstraint

metadata = MetaData()

estimates = Table(
    "estimates",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("actuator_id", Text, nullable=False),
    Column("window_id", Text, nullable=False),
    Column("stored_at", Text, nullable=False),
    Column("result", Text, nullable=False),
    Column("content_sha256", Text),
    Column("flight_id", Text),
    Column("sensor_zero", Text),
    Column("inertia_read", Text),
    UniqueConstraint("actuator_id", "window_id", name="estimates_actuator_window"),
    sqlite_autoincrement=True,
)
Index("estimates_by_actuator", estimates.c.actuator_id, estimates.c.id)

calibrations = Table(
    "calibrations",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("actuator_id", Text, nullable=False),
    Column("stored_at", Text, nullable=False),
    Column("report", Text, nullable=False),
    sqlite_autoincrement=True,
)
Index("calibrations_by_actuator", calibrations.c.actuator_id, calibrations.c.id)

actuators = Table(
    "actuators",
    metadata,
    Column("actuator_id", Text, nullable=False),
    Column("version", Integer, nullable=False),
    Column("stored_at", Text, nullable=False),
    Column("document", Text, nullable=False),
    PrimaryKeyConstraint("actuator_id", "version", name="actuators_version"),
)

withdrawals = Table(
    "withdrawals",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("actuator_id", Text, nullable=False),
    Column("window_id", Text, nullable=False),
    Column("withdrawn_at", Text, nullable=False),
    Column("reason", Text, nullable=False),
    Column("stored_at", Text, nullable=False),
    Column("content_sha256", Text),
    Column("result", Text, nullable=False),
    sqlite_autoincrement=True,
)
Index("withdrawals_by_actuator", withdrawals.c.actuator_id, withdrawals.c.id)

summaries = Table(
    "summaries",
    metadata,
    Column("actuator_id", Text, primary_key=True),
    Column("state", Text, nullable=False),
    Column("urgency", Integer, nullable=False),
    Column("soonest", Float),
    Column("row", Text, nullable=False),
)
