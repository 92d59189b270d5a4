"""who: the person behind each record — a job's tool beside its submitter, who made a run and who
last wrote its notes

Revision ID: 0011
Revises: 0010
Create Date: 2026-12-06 10:00:00

Before people had tokens, ``jobs.submitted_by`` was the ``X-Parkour-Client`` header (else the
client's address); from here on it is the person, and the header, which only labels the tool, is
``submitted_via``. Records made before stay as they were: who made them was not kept (null).
"""

import sqlalchemy as sa
from alembic import op

revision = "0011"
down_revision = "0010"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("jobs") as batch:
        batch.add_column(sa.Column("submitted_via", sa.String(length=64), nullable=True))
    with op.batch_alter_table("runs") as batch:
        batch.add_column(sa.Column("created_by", sa.String(length=64), nullable=True))
        batch.add_column(sa.Column("notes_by", sa.String(length=64), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("runs") as batch:
        batch.drop_column("notes_by")
        batch.drop_column("created_by")
    with op.batch_alter_table("jobs") as batch:
        batch.drop_column("submitted_via")
