"""backend/store/database.py: engines, and migrations that skip Alembic at the newest revision."""

import sys

from alembic.script import ScriptDirectory
from sqlalchemy import text

from backend.store.database import (
    MIGRATIONS,
    SCHEMA_HEAD,
    alembic_config,
    make_engine,
    migrate,
    schema_revision,
    sqlite_url,
)


def test_schema_head_is_alembics_newest_revision(tmp_path):
    engine = make_engine(sqlite_url(tmp_path))
    head = ScriptDirectory.from_config(alembic_config(engine)).get_current_head()
    assert head == SCHEMA_HEAD, f"a migration was added in {MIGRATIONS}: set SCHEMA_HEAD = {head!r}"


def test_migrate_upgrades_a_new_database_and_an_old_one(empty_database_url):
    engine = make_engine(empty_database_url)
    assert schema_revision(engine) is None
    migrate(engine, "0003")
    assert schema_revision(engine) == "0003"
    migrate(engine)
    assert schema_revision(engine) == SCHEMA_HEAD
    with engine.connect() as connection:  # 0004's column is there: the upgrade really ran
        connection.execute(text("SELECT notes FROM runs"))
    engine.dispose()


def test_a_database_at_the_head_starts_without_alembic(tmp_path, monkeypatch):
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    monkeypatch.setitem(sys.modules, "alembic", None)  # importing alembic now raises ImportError
    migrate(engine)
    assert schema_revision(engine) == SCHEMA_HEAD
