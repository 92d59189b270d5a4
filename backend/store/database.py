"""The database: engine, sessions, and migrations applied at start-up.

SQLite by default (a file in the data directory, WAL journal, foreign keys on); any
SQLAlchemy URL, e.g. PostgreSQL through ``DATABASE_URL``, with no code change. The schema
is Alembic's: :func:`migrate` upgrades to the newest revision before the service starts. Alembic
is imported only when there is something to upgrade: a database already at :data:`SCHEMA_HEAD`
starts without it (a third of a second of the service's start-up).

Integrity (issue 14): :func:`lock_for_write` takes the write lock before a change reads what it
depends on, so concurrent edits of one record serialise; a write on a full disk raises
:class:`StorageFull` (the API answers 507), whichever database and statement hit it; the WAL is
kept to :data:`JOURNAL_SIZE_LIMIT` after checkpoints; and a small reserve file next to the SQLite
database is given back when a delete finds the disk full, so deleting — the way to free space —
still works (:func:`freeing_space`).
"""

from __future__ import annotations

import errno
import logging
import os
import sqlite3
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from sqlalchemy import Engine, create_engine, event, inspect, make_url, text
from sqlalchemy.exc import OperationalError
from sqlalchemy.orm import Session, sessionmaker

if TYPE_CHECKING:
    from alembic.config import Config

MIGRATIONS = Path(__file__).resolve().parent / "migrations"
# The newest migration's revision. tests/backend/store/test_database.py fails when a migration is
# added without moving this: a stale value would let a database one revision behind start unmigrated.
SCHEMA_HEAD = "0014"

log = logging.getLogger("parkourlab.store")
T = TypeVar("T")

FULL_MESSAGE = "the disk holding the database is full: free space (e.g. delete runs) and retry"
SQLITE_FULL = 13  # the primary result code; extended codes keep it in their low byte
POSTGRES_DISK_FULL = "53100"  # SQLSTATE of PostgreSQL's DiskFull
FULL_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT})
# The WAL file is cut back to this size when a checkpoint resets it: without a limit it keeps the
# size of its largest burst for ever (every write between two checkpoints, more while a long read
# holds a snapshot). 4 MiB is a little over SQLite's automatic checkpoint (1000 pages), so in
# steady state the file is neither cut nor regrown: writes after a reset overwrite space it has.
JOURNAL_SIZE_LIMIT = 4 * 2**20
# Space set aside next to the SQLite file, given back when a delete finds the disk full: what the
# delete's own WAL frames and the checkpoint that folds the WAL into the database need.
RESERVE_BYTES = 8 * 2**20
RESERVE_SUFFIX = "-reserve"
MIN_RESERVE_STEP = 64 * 1024
# The SQLite files whose disk a write found full, with no space returned since: kept by file, not
# by engine (engines on one file share its disk, and the engine's own listeners need not hold it).
_DISK_FULL: set[Path] = set()
PAGE_CAP = "parkourlab.page_cap"  # a pooled connection's info: its max_page_count is capped
NO_PAGE_CAP = 4294967294  # SQLite's largest max_page_count (it lowers a larger one to its own limit)


class StorageFull(OperationalError):
    """A write failed because the disk (or the database server's disk) is full; raised in place of
    the driver's error by every engine :func:`make_engine` builds (the API answers 507)."""

    def __str__(self) -> str:
        return FULL_MESSAGE


def is_storage_full(error: BaseException | None) -> bool:
    """Whether ``error`` — or what it wraps (``.orig``, its cause or context) — says the disk is full:
    :class:`StorageFull`, SQLite's SQLITE_FULL ("database or disk is full"), PostgreSQL's DiskFull
    (SQLSTATE 53100), an OSError ENOSPC or EDQUOT."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        seen.add(id(error))
        if isinstance(error, StorageFull):
            return True
        if isinstance(error, OSError) and error.errno in FULL_ERRNOS:
            return True
        if isinstance(error, sqlite3.Error) and (
            (getattr(error, "sqlite_errorcode", 0) or 0) & 0xFF == SQLITE_FULL or "disk is full" in str(error)
        ):
            return True
        if POSTGRES_DISK_FULL in (getattr(error, "sqlstate", None), getattr(error, "pgcode", None)):
            return True
        wrapped = getattr(error, "orig", None)
        if isinstance(wrapped, BaseException) and id(wrapped) not in seen:
            error = wrapped
        else:
            error = error.__cause__ or error.__context__
    return False


def sqlite_url(data_dir: Path) -> str:
    return f"sqlite:///{Path(data_dir) / 'parkourlab.sqlite3'}"


def make_engine(url: str) -> Engine:
    database = sqlite_file(url)  # the listeners below keep this, not the engine
    if url.startswith("sqlite"):
        engine = create_engine(url, connect_args={"check_same_thread": False, "timeout": 30})

        @event.listens_for(engine, "connect")
        def _sqlite_pragmas(connection, _record):
            cursor = connection.cursor()
            cursor.execute("PRAGMA journal_mode=WAL")  # readers never block the writer
            cursor.execute("PRAGMA foreign_keys=ON")
            cursor.execute("PRAGMA synchronous=NORMAL")  # durable at checkpoints; safe with WAL
            cursor.execute(f"PRAGMA journal_size_limit={JOURNAL_SIZE_LIMIT}")
            cursor.close()

        @event.listens_for(engine, "checkout")
        def _page_cap(dbapi_connection, record, _proxy):
            if database is not None:
                apply_page_cap(database, dbapi_connection, record.info)

    else:
        engine = create_engine(url, pool_pre_ping=True)

    @event.listens_for(engine, "handle_error")
    def _storage_full(context):
        # Every statement, commit and connect of this engine: a full disk is one exception, whatever
        # the driver called it, for the API's table (507) and for the job runner alike.
        if is_storage_full(context.original_exception):
            if database is not None:
                _DISK_FULL.add(database)  # connections checked out from now on are capped
            raise StorageFull(context.statement, context.parameters, context.original_exception)

    return engine


def session_factory(engine: Engine) -> sessionmaker[Session]:
    return sessionmaker(engine, expire_on_commit=False)


@contextmanager
def opened_store(url: str) -> Iterator[sessionmaker[Session]]:
    """Sessions on the database at ``url``, migrated to the newest schema: a command's way in
    (``parkour calibrate``); the service opens its own in ``create_app``."""
    engine = make_engine(url)
    try:
        migrate(engine)
        yield session_factory(engine)
    finally:
        engine.dispose()


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
    try:
        current = schema_revision(engine)
    except OperationalError:
        # A clean stop removed the WAL and its shared-memory file; on a full disk SQLite cannot make
        # them again, so the database would not even open. The reserve deletes need makes room.
        database = database_file(engine)
        if database is None or free_bytes(database.parent) >= JOURNAL_SIZE_LIMIT or not release_reserve(engine):
            raise
        current = schema_revision(engine)
    if revision == "head" and current == SCHEMA_HEAD:
        return
    from alembic import command

    command.upgrade(alembic_config(engine), revision)


def apply_page_cap(database: Path, dbapi_connection, info: dict) -> None:
    """While the disk is full, a SQLite connection may not grow the database (``PRAGMA
    max_page_count`` = its size): writes that fit in pages deletes freed go through, the others
    fail at once with SQLITE_FULL (507) instead of piling up in the WAL, whose later checkpoint would
    need disk space that is not there — eating the reserve that deletes need. The cap is lifted at
    the first checkout after space returned: the reserve whole again and a WAL's worth free."""
    full = database in _DISK_FULL
    if full and _space_returned(database):
        _DISK_FULL.discard(database)
        full = False
        log.warning("space returned on the disk holding %s: the database may grow again", database)
    if full == info.get(PAGE_CAP, False):
        return
    cursor = dbapi_connection.cursor()
    try:
        if full:
            (pages,) = cursor.execute("PRAGMA page_count").fetchone()
            cursor.execute(f"PRAGMA max_page_count={pages}")
        else:
            cursor.execute(f"PRAGMA max_page_count={NO_PAGE_CAP}")
    finally:
        cursor.close()
    info[PAGE_CAP] = full


def space_returned(engine: Engine) -> bool:
    """Whether the disk holding the SQLite database has room again: the reserve whole (topped up
    here if it can be) and a WAL's worth (:data:`JOURNAL_SIZE_LIMIT`) free besides."""
    database = database_file(engine)
    return True if database is None else _space_returned(database)


def _space_returned(database: Path) -> bool:
    try:
        reserved = _ensure_reserve(database, RESERVE_BYTES, JOURNAL_SIZE_LIMIT)
        return reserved >= RESERVE_BYTES and free_bytes(database.parent) >= JOURNAL_SIZE_LIMIT
    except OSError:
        return False


def ping(session: Session) -> str:
    """Ask the database for something (``SELECT 1``): its dialect's name, or the driver's error."""
    session.execute(text("SELECT 1"))
    return session.get_bind().dialect.name


def lock_for_write(session: Session) -> None:
    """Take the database's write lock for the session's transaction now, before it reads what its
    change depends on; held until commit or rollback, so two such changes never interleave.

    SQLite: ``BEGIN IMMEDIATE`` (waiting up to the busy timeout; a transaction that has already
    written holds the lock). Other databases lock the rows the change reads instead: load them with
    ``with_for_update`` (``SELECT … FOR UPDATE``), as :func:`backend.repositories.common.locked` does."""
    connection = session.connection()
    if connection.dialect.name == "sqlite" and not connection.connection.dbapi_connection.in_transaction:
        connection.exec_driver_sql("BEGIN IMMEDIATE")


def checkpoint(engine: Engine, mode: str = "TRUNCATE") -> tuple[int, int, int] | None:
    """Fold SQLite's WAL into the database (``PRAGMA wal_checkpoint(mode)``): ``(busy, wal frames,
    frames checkpointed)``; TRUNCATE also cuts the WAL file to nothing. None on other databases."""
    if engine.dialect.name != "sqlite":
        return None
    if mode not in ("PASSIVE", "FULL", "RESTART", "TRUNCATE"):
        raise ValueError(f"unknown checkpoint mode {mode!r}")
    with engine.connect() as connection:
        busy, frames, done = connection.exec_driver_sql(f"PRAGMA wal_checkpoint({mode})").one()
    return busy, frames, done


def database_file(engine: Engine) -> Path | None:
    """The SQLite database's file, or None (another database, or one in memory)."""
    return sqlite_file(engine.url)


def sqlite_file(url) -> Path | None:
    """The SQLite database file of ``url`` (a string or URL), or None (another database, or one in memory)."""
    url = make_url(url)
    name = url.database
    if url.get_backend_name() != "sqlite" or not name or name == ":memory:" or name.startswith("file:"):
        return None
    return Path(name)


def reserve_file(engine: Engine) -> Path | None:
    """Where the space reserve lives: next to the SQLite file, on the same filesystem."""
    database = database_file(engine)
    return None if database is None else _reserve_of(database)


def _reserve_of(database: Path) -> Path:
    return database.with_name(database.name + RESERVE_SUFFIX)


def free_bytes(path: Path) -> int:
    """Bytes free to this process on the filesystem holding ``path``."""
    stats = os.statvfs(path)
    return stats.f_bavail * stats.f_frsize


def ensure_reserve(engine: Engine, size: int = RESERVE_BYTES, keep_free: int = JOURNAL_SIZE_LIMIT) -> int:
    """Set the space reserve aside, or top it up, to ``size`` bytes really allocated, leaving at
    least ``keep_free`` bytes free (room for the WAL to grow to its limit: making the reserve never
    fills the disk); the bytes reserved now. On a disk short of space it is smaller, or none."""
    database = database_file(engine)
    return 0 if database is None else _ensure_reserve(database, size, keep_free)


def _ensure_reserve(database: Path, size: int, keep_free: int) -> int:
    path = _reserve_of(database)
    current = path.stat().st_size if path.exists() else 0
    if current >= size:
        return current
    try:
        target = min(size, current + free_bytes(path.parent) - keep_free)
        if target - current < MIN_RESERVE_STEP:
            return current
        with path.open("r+b" if current else "wb") as out:
            try:
                os.posix_fallocate(out.fileno(), 0, target)
                os.fsync(out.fileno())
            except OSError:
                out.truncate(current)  # no half-made reserve: what was there stays
                raise
    except OSError as error:
        if not is_storage_full(error):  # e.g. a filesystem without fallocate: run without a reserve
            log.warning("could not set aside a space reserve at %s: %s", path, error)
        return current
    return target


def release_reserve(engine: Engine) -> bool:
    """Give the space reserve back to the filesystem; whether there was one."""
    path = reserve_file(engine)
    if path is None or not path.exists():
        return False
    path.unlink()
    log.warning("the disk holding %s is full: released its %s reserve to let a delete through", path.parent, path)
    return True


def after_storage_full(engine: Engine) -> None:
    """What to do after a write failed with :class:`StorageFull` (and was rolled back): fold the
    WAL into the database (a PASSIVE checkpoint, which waits for nobody), so the next write
    overwrites the WAL from its start instead of growing it — on a full disk, with pages freed by
    deletes inside the database, that is the difference between a retry working and failing.
    Never raises: with no room even for the checkpoint, the next write fails as it would have."""
    _checkpoint_quietly(engine, "PASSIVE", logging.DEBUG)  # failing is expected on a full disk


def freeing_space(session: Session, change: Callable[[], T]) -> T:
    """Run ``change`` (a delete that commits) so that it works on a full disk: deleting is how
    space is freed, so it must not need any.

    If ``change`` raises :class:`StorageFull`, it is rolled back and run again after a RESTART
    checkpoint (the WAL folded into the database and its file reused from the start: often room
    enough for a delete); if that fails too, again after giving the reserve back (the checkpoint
    may need to grow the database file, the delete to append to the WAL). Then the WAL is folded
    once more, so the pages the delete freed serve the next writes. Raises StorageFull when nothing
    helps (no reserve left, or not SQLite). What the checkpoints leave free is set aside again at
    once (the reserve is topped up again when space returns: :func:`space_returned`)."""
    try:
        return change()
    except StorageFull:
        session.rollback()
        engine = session.get_bind()
        if engine.dialect.name != "sqlite":
            raise
        return _change_on_a_full_disk(session, engine, change)


def _change_on_a_full_disk(session: Session, engine: Engine, change: Callable[[], T]) -> T:
    _checkpoint_quietly(engine, "RESTART")
    try:
        result = change()
    except StorageFull:
        session.rollback()
        if not release_reserve(engine):
            raise
        _checkpoint_quietly(engine, "RESTART")
        result = change()
    _checkpoint_quietly(engine, "RESTART")
    # Set aside again at once what the checkpoints left free, before other writes take it: the
    # delete freed pages inside the database, which the next writes reuse, not on the disk.
    ensure_reserve(engine, keep_free=0)
    return result


def _checkpoint_quietly(engine: Engine, mode: str, level: int = logging.WARNING) -> None:
    try:
        checkpoint(engine, mode)
    except OperationalError as error:  # StorageFull among them: no room even for the checkpoint
        log.log(level, "a %s checkpoint of %s failed: %s", mode, database_file(engine), error)
