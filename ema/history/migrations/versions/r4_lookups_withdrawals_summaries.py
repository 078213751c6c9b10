"""Round 4: lookup columns instead of JSON paths, withdrawn windows kept, the fleet view's summaries.

The columns a lookup before every estimate reads (``flight_id``, ``sensor_zero``, ``inertia_read``)
are filled from each stored result once, here, in Python: the same on every database.

Revision ID: r4
Revises: r3
"""

import json

import sqlalchemy as sa
from alembic import op

revision = "r4"
down_revision = "r3"
branch_labels = None
depends_on = None

BATCH = 500


def upgrade() -> None:
    bind = op.get_bind()
    if bind.dialect.name == "sqlite":  # round 3's SQLite-only indexes over JSON paths
        op.execute("DROP INDEX IF EXISTS estimates_sensor_zeros")
        op.execute("DROP INDEX IF EXISTS estimates_inertia_reads")
    with op.batch_alter_table("estimates") as batch:
        batch.add_column(sa.Column("flight_id", sa.Text))
        batch.add_column(sa.Column("sensor_zero", sa.Text))
        batch.add_column(sa.Column("inertia_read", sa.Text))
    _fill_lookups(bind)
    op.create_index("estimates_by_flight", "estimates", ["actuator_id", "flight_id"])
    op.create_table(
        "withdrawals",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("actuator_id", sa.Text, nullable=False),
        sa.Column("window_id", sa.Text, nullable=False),
        sa.Column("withdrawn_at", sa.Text, nullable=False),
        sa.Column("reason", sa.Text, nullable=False),
        sa.Column("stored_at", sa.Text, nullable=False),
        sa.Column("content_sha256", sa.Text),
        sa.Column("result", sa.Text, nullable=False),
        sqlite_autoincrement=True,
    )
    op.create_index("withdrawals_by_actuator", "withdrawals", ["actuator_id", "id"])
    op.create_table(
        "summaries",
        sa.Column("actuator_id", sa.Text, primary_key=True),
        sa.Column("state", sa.Text, nullable=False),
        sa.Column("urgency", sa.Integer, nullable=False),
        sa.Column("soonest", sa.Float),
        sa.Column("row", sa.Text, nullable=False),
    )


def _fill_lookups(bind: sa.Connection) -> None:
    """Each stored result's flight_id, sensor_zero and inertia_read, in their columns (null where absent)."""
    table = sa.table(
        "estimates",
        sa.column("id", sa.Integer),
        sa.column("result", sa.Text),
        sa.column("flight_id", sa.Text),
        sa.column("sensor_zero", sa.Text),
        sa.column("inertia_read", sa.Text),
    )
    last = -1
    while True:
        rows = bind.execute(
            sa.select(table.c.id, table.c.result).where(table.c.id > last).order_by(table.c.id).limit(BATCH)
        ).all()
        if not rows:
            return
        for row_id, result in rows:
            window = json.loads(result).get("window") or {}
            values = {name: window.get(name) for name in ("sensor_zero", "inertia_read")}
            bind.execute(
                sa.update(table)
                .where(table.c.id == row_id)
                .values(
                    flight_id=window.get("flight_id"),
                    **{name: None if value is None else json.dumps(value) for name, value in values.items()},
                )
            )
        last = rows[-1][0]


def downgrade() -> None:
    op.drop_table("summaries")
    op.drop_index("withdrawals_by_actuator", "withdrawals")
    op.drop_table("withdrawals")
    op.drop_index("estimates_by_flight", "estimates")
    with op.batch_alter_table("estimates") as batch:
        for name in ("inertia_read", "sensor_zero", "flight_id"):
            batch.drop_column(name)
