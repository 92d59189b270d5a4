"""The database: engine, sessions, and migrations applied at start-up.

SQLite by default (a file in the data directory, WAL journal, foreign keys on); any
SQLAlchemy URL, e.g. PostgreSQL through ``DATABASE_URL``, with no code change. The schema
is Alembic's: :func:`migrate` upgrades to the newest revision before the service starts. Alembic
is imported only when there is something to upgrade: a database already at :data:`SCHEMA_HEAD`
starts without it (a third of a second of the service's start-up).

Concurrent edits (issue 14): :func:`lock_for_write` takes the write lock before a change reads what
it depends on, so concurrent edits of one record serialise.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from sqlalchemy import Engine, create_engine, event, inspect, text
from sqlalchemy.orm import Session, sessionmaker

if TYPE_CHECKING:
    from alembic.config import Config

MIGRATIONS = Path(__file__).resolve().parent / "migrations"
# The newest migration's revision. tests/backend/store/test_database.py fails when a migration is
# added without moving this: a stale value would let a database one revision behind start unmigrated.
SCHEMA_HEAD = "0005"


def sqlite_url(data_dir: Path) -> str:
    return f"sqlite:///{Path(data_dir) / 'parkourlab.sqlite3'}"


def make_engine(url: str) -> Engine:
    if url.startswith("sqlite"):
        engine = create_engine(url, connect_args={"check_same_thread": False, "timeout": 30})

        @event.listens_for(engine, "connect")
        def _sqlite_pragmas(connection, _record):
            cursor = connection.cursor()
            cursor.execute("PRAGMA journal_mode=WAL")  # readers never block the writer
            cursor.execute("PRAGMA foreign_keys=ON")
            cursor.execute("PRAGMA synchronous=NORMAL")  # durable at checkpoints; safe with WAL
            cursor.close()

        return engine
    return create_engine(url, pool_pre_ping=True)


def session_factory(engine: Engine) -> sessionmaker[Session]:
    return sessionmaker(engine, expire_on_commit=False)


def alembic_config(engine: Engine) -> Config:
    from alembic.config import Config

    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    config.attributes["engine"] = engine
    return config


def schema_revision(engine: Engine) -> str | None:
    """The database's Alembic revision, or None for a database Alembic has not touched."""
    with engine.connect() as connection:
        if not inspect(connection).has_table("alembic_version"):
            return None
        return connection.execute(text("SELECT version_num FROM alembic_version")).scalar()


def migrate(engine: Engine, revision: str = "head") -> None:
    """Upgrade the schema to ``revision`` (default: the newest)."""
    if revision == "head" and schema_revision(engine) == SCHEMA_HEAD:
        return
    from alembic import command

    command.upgrade(alembic_config(engine), revision)


def lock_for_write(session: Session) -> None:
    """Take the database's write lock for the session's transaction now, before it reads what its
    change depends on; held until commit or rollback, so two such changes never interleave.

    SQLite: ``BEGIN IMMEDIATE`` (waiting up to the busy timeout; a transaction that has already
    written holds the lock). Other databases lock the rows the change reads instead: load them with
    ``with_for_update`` (``SELECT … FOR UPDATE``), as :func:`backend.services.records.locked` does."""
    connection = session.connection()
    if connection.dialect.name == "sqlite" and not connection.connection.dbapi_connection.in_transaction:
        connection.exec_driver_sql("BEGIN IMMEDIATE")
