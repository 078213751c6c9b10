"""The history as round 3 left it: estimates keyed by (actuator_id, window_id), calibrations, actuators.

Revision ID: r3
Revises:
"""

import sqlalchemy as sa
from alembic import op

revision = "r3"
down_revision = None
branch_labels = None
depends_on = None


def upgrade() -> None:
    _per_actuator(
        "estimates",
        _required("window_id"),
        _required("stored_at"),
        _required("result"),
        sa.Column("content_sha256", sa.Text),
        sa.UniqueConstraint("actuator_id", "window_id", name="estimates_actuator_window"),
    )
    _per_actuator("calibrations", _required("stored_at"), _required("report"))
    op.create_table(
        "actuators",
        _required("actuator_id"),
        _required("version", sa.Integer),
        _required("stored_at"),
        _required("document"),
        sa.PrimaryKeyConstraint("actuator_id", "version", name="actuators_version"),
    )


def _required(name: str, kind: type[sa.Integer] | type[sa.Text] = sa.Text) -> sa.Column:
    return sa.Column(name, kind, nullable=False)


def _per_actuator(name: str, *columns: sa.Column | sa.UniqueConstraint) -> None:
    """A table of rows appended per actuator (an id in the order stored, the actuator_id, ``columns``), indexed to
    be read by actuator in that order: as round 3 made them, kept here so that later helpers cannot change it."""
    op.create_table(
        name,
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        _required("actuator_id"),
        *columns,
        sqlite_autoincrement=True,
    )
    op.create_index(f"{name}_by_actuator", name, ["actuator_id", "id"])


def downgrade() -> None:
    for table in ("actuators", "calibrations", "estimates"):
        op.drop_table(table)
