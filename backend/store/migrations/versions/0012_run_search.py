"""run_search: an index for the search of notes and tags (History's ``q``)

``q`` found text in every run's notes by scanning them all: at 100,000 runs, 10 clients searching
at random took a plain History page from a p50 of 8 ms to 3.9 s (issue 40). Now it reads an index:

- SQLite: ``run_search``, an FTS5 table with the trigram tokenizer (any substring of three
  characters or more; case-insensitive), a row per run (rowid = the run's id) holding its notes
  and its tags (one per line), kept by triggers on ``runs`` and ``run_tags``;
- PostgreSQL: ``pg_trgm``'s GIN indexes on ``runs.notes`` and ``run_tags.tag``, which the same
  ``ILIKE '%…%'`` reads. Where the extension cannot be created (a role without the right), the
  search works as before, by scanning, and the migration says so.

Revision ID: 0012
Revises: 0011
Create Date: 2026-12-06 10:30:00
"""

import logging

from alembic import op
from sqlalchemy.exc import DBAPIError

revision = "0012"
down_revision = "0011"
branch_labels = None
depends_on = None

log = logging.getLogger("alembic.runtime.migration")
TAGS_OF = "(SELECT group_concat(tag, char(10)) FROM run_tags WHERE run_id = {run})"  # one tag per line
SQLITE = [
    "CREATE VIRTUAL TABLE run_search USING fts5(notes, tags, tokenize = 'trigram')",
    f"INSERT INTO run_search (rowid, notes, tags) SELECT id, notes, coalesce({TAGS_OF.format(run='runs.id')}, '') "
    "FROM runs",
    "CREATE TRIGGER run_search_insert AFTER INSERT ON runs "
    "BEGIN INSERT INTO run_search (rowid, notes, tags) VALUES (NEW.id, NEW.notes, ''); END",
    "CREATE TRIGGER run_search_notes AFTER UPDATE OF notes ON runs "
    "BEGIN UPDATE run_search SET notes = NEW.notes WHERE rowid = NEW.id; END",
    "CREATE TRIGGER run_search_delete AFTER DELETE ON runs BEGIN DELETE FROM run_search WHERE rowid = OLD.id; END",
    "CREATE TRIGGER run_search_tag_insert AFTER INSERT ON run_tags "
    f"BEGIN UPDATE run_search SET tags = coalesce({TAGS_OF.format(run='NEW.run_id')}, '') "
    "WHERE rowid = NEW.run_id; END",
    "CREATE TRIGGER run_search_tag_delete AFTER DELETE ON run_tags "
    f"BEGIN UPDATE run_search SET tags = coalesce({TAGS_OF.format(run='OLD.run_id')}, '') "
    "WHERE rowid = OLD.run_id; END",
    "CREATE TRIGGER run_search_tag_update AFTER UPDATE ON run_tags "
    f"BEGIN UPDATE run_search SET tags = coalesce({TAGS_OF.format(run='OLD.run_id')}, '') WHERE rowid = OLD.run_id; "
    f"UPDATE run_search SET tags = coalesce({TAGS_OF.format(run='NEW.run_id')}, '') WHERE rowid = NEW.run_id; END",
]
SQLITE_TRIGGERS = ("run_search_insert", "run_search_notes", "run_search_delete", "run_search_tag_insert",
                   "run_search_tag_delete", "run_search_tag_update")  # fmt: skip
POSTGRESQL_INDEXES = {"ix_runs_notes_trgm": ("runs", "notes"), "ix_run_tags_tag_trgm": ("run_tags", "tag")}


def upgrade() -> None:
    bind = op.get_bind()
    if bind.dialect.name == "sqlite":
        for statement in SQLITE:
            op.execute(statement)
        return
    try:
        with bind.begin_nested():  # a refusal must not abort the migration's transaction
            op.execute("CREATE EXTENSION IF NOT EXISTS pg_trgm")
    except DBAPIError as error:
        log.warning("pg_trgm cannot be created (%s): History's search will scan the notes", error.orig)
        return
    for name, (table, column) in POSTGRESQL_INDEXES.items():
        op.execute(f"CREATE INDEX {name} ON {table} USING gin ({column} gin_trgm_ops)")


def downgrade() -> None:
    if op.get_bind().dialect.name == "sqlite":
        for name in SQLITE_TRIGGERS:
            op.execute(f"DROP TRIGGER {name}")
        op.execute("DROP TABLE run_search")
        return
    for name in POSTGRESQL_INDEXES:
        op.execute(f"DROP INDEX IF EXISTS {name}")
