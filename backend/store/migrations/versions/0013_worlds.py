"""worlds: the lab's worlds stored by name, and the world each run and job ran in

Revision ID: 0013
Revises: 0012
Create Date: 2026-12-06 19:40:00

A world (docs/model.md §8) is stored once, as posted, and referenced: ``runs.world_id`` and
``jobs.world_id``, null for everything stored before worlds (parallel walls). On SQLite the
columns are added in place (``ADD COLUMN ... REFERENCES``): a batch rebuild of ``runs`` would
drop the triggers that keep History's search index (0012). The keys take no ``ON DELETE``: a world
in use is refused by the service (naming a run or job that uses it), the key is the backstop.
"""

import sqlalchemy as sa
from alembic import op

revision = "0013"
down_revision = "0012"
branch_labels = None
depends_on = None

USERS = ("runs", "jobs")


def upgrade() -> None:
    op.create_table(
        "worlds",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("name", sa.String(length=200), nullable=False),
        sa.Column("document", sa.JSON(), nullable=False),
        sa.Column("source", sa.String(length=200), nullable=False),
        sa.Column("created_at", sa.DateTime(timezone=True), nullable=False),
        sa.Column("created_by", sa.String(length=64), nullable=True),
        sa.PrimaryKeyConstraint("id"),
        sa.UniqueConstraint("name"),
    )
    op.create_index("ix_worlds_created_at", "worlds", ["created_at"])
    sqlite = op.get_bind().dialect.name == "sqlite"
    for table in USERS:
        if sqlite:
            op.execute(f"ALTER TABLE {table} ADD COLUMN world_id INTEGER REFERENCES worlds (id)")
        else:
            op.add_column(table, sa.Column("world_id", sa.Integer(), nullable=True))
            op.create_foreign_key(f"fk_{table}_world_id_worlds", table, "worlds", ["world_id"], ["id"])
        op.create_index(f"ix_{table}_world_id", table, ["world_id"])


def downgrade() -> None:
    for table in USERS:
        op.drop_index(f"ix_{table}_world_id", table_name=table)
        if op.get_bind().dialect.name == "sqlite":
            op.execute(f"ALTER TABLE {table} DROP COLUMN world_id")
        else:
            op.drop_constraint(f"fk_{table}_world_id_worlds", table, type_="foreignkey")
            op.drop_column(table, "world_id")
    op.drop_index("ix_worlds_created_at", table_name="worlds")
    op.drop_table("worlds")
