"""run_journal: a live robot run's data appended while it runs, so a crash loses at most a second

Revision ID: 0005
Revises: 0004
Create Date: 2026-12-01 16:30:00
"""

import sqlalchemy as sa
from alembic import op

revision = "0005"
down_revision = "0004"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "run_journal",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("run_id", sa.Integer(), nullable=False),
        sa.Column("written_at", sa.DateTime(timezone=True), nullable=False),
        sa.Column("data", sa.JSON(), nullable=False),
        sa.ForeignKeyConstraint(["run_id"], ["runs.id"], ondelete="CASCADE"),
        sa.PrimaryKeyConstraint("id"),
    )
    op.create_index(op.f("ix_run_journal_run_id"), "run_journal", ["run_id"], unique=False)


def downgrade() -> None:
    op.drop_index(op.f("ix_run_journal_run_id"), table_name="run_journal")
    op.drop_table("run_journal")
