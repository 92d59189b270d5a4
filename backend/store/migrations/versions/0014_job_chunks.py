"""job_chunks: the finished chunks of a chunked job, so that a restart computes only those missing

Revision ID: 0014
Revises: 0013
Create Date: 2026-12-06 22:00:00

A foothold study (a chunk per world) and the trials in a world (a chunk per block of trials) store
each chunk's JSON result as it finishes, keyed by (job, chunk index): killed mid-job, the next
start reads them back and computes the rest; the job's result is made from all of them.
"""

import sqlalchemy as sa
from alembic import op

revision = "0014"
down_revision = "0013"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "job_chunks",
        sa.Column("job_id", sa.Integer(), nullable=False),
        sa.Column("index", sa.Integer(), nullable=False),
        sa.Column("result", sa.JSON(), nullable=False),
        sa.ForeignKeyConstraint(["job_id"], ["jobs.id"], ondelete="CASCADE"),
        sa.PrimaryKeyConstraint("job_id", "index"),
    )


def downgrade() -> None:
    op.drop_table("job_chunks")
