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
    op.create_table(
        "estimates",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("actuator_id", sa.Text, nullable=False),
        sa.Column("window_id", sa.Text, nullable=False),
        sa.Column("stored_at", sa.Text, nullable=False),
        sa.Column("result", sa.Text, nullable=False),
        sa.Column("content_sha256", sa.Text),
        sa.UniqueConstraint("actuator_id", "window_id", name="estimates_actuator_window"),
        sqlite_autoincrement=True,
    )
    op.create_index("estimates_by_actuator", "estimates", ["actuator_id", "id"])
    op.create_table(
        "calibrations",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("actuator_id", sa.Text, nullable=False),
        sa.Column("stored_at", sa.Text, nullable=False),
        sa.Column("report", sa.Text, nullable=False),
        sqlite_autoincrement=True,
    )
    op.create_index("calibrations_by_actuator", "calibrations", ["actuator_id", "id"])
    op.create_table(
        "actuators",
        sa.Column("actuator_id", sa.Text, nullable=False),
        sa.Column("version", sa.Integer, nullable=False),
        sa.Column("stored_at", sa.Text, nullable=False),
        sa.Column("document", sa.Text, nullable=False),
        sa.PrimaryKeyConstraint("actuator_id", "version", name="actuators_version"),
    )


def downgrade() -> None:
    for table in ("actuators", "calibrations", "estimates"):
        op.drop_table(table)
