"""Round 7: what a window lends the actuator's other windows kept whatever the actuator's kind.

The lookup columns round 4 named for the rotary's loans, ``sensor_zero`` (to the windows of a flight) and
``inertia_read`` (to every window of the actuator), become ``lent_to_flight`` and ``lent_to_actuator``: the same
JSON in each row, which the actuator's kind reads (``ema.kinds.base.Lent``). Renamed in place: nothing stored moves.

Revision ID: r5
Revises: r4
"""

from alembic import op

revision = "r5"
down_revision = "r4"
branch_labels = None
depends_on = None

RENAMED = (("sensor_zero", "lent_to_flight"), ("inertia_read", "lent_to_actuator"))


def upgrade() -> None:
    with op.batch_alter_table("estimates") as batch:
        for old, new in RENAMED:
            batch.alter_column(old, new_column_name=new)


def downgrade() -> None:
    with op.batch_alter_table("estimates") as batch:
        for old, new in RENAMED:
            batch.alter_column(new, new_column_name=old)
