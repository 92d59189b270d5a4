"""backend/store/database.py on a full disk and under a long WAL (issue 14).

- every way a driver says "disk full" is one :class:`StorageFull` (``is_storage_full``);
- the WAL is cut back to ``JOURNAL_SIZE_LIMIT`` after a checkpoint (it used to keep its largest size);
- on a real full filesystem (a small tmpfs, root only) deletes go through — the reserve given
  back once, the database capped at its size while the disk is full — writes fit in the pages
  deletes freed, and everything resumes when space returns. Before: every write and every delete
  failed (``database or disk is full``, a bare 500 in the API) and nothing could free space.
"""

import errno
import sqlite3
import threading

import pytest
from sqlalchemy import event, text
from sqlalchemy.exc import IntegrityError, OperationalError

from backend.repositories import runs as run_store
from backend.schemas import RunCreate
from backend.services import runs
from backend.store import database
from backend.store.database import (
    FULL_MESSAGE,
    JOURNAL_SIZE_LIMIT,
    RESERVE_BYTES,
    StorageFull,
    checkpoint,
    ensure_reserve,
    is_storage_full,
    make_engine,
    migrate,
    reserve_file,
    session_factory,
    sqlite_url,
)
from tests.backend.disk import fill, free_bytes, tmpfs


def _sqlite_full_error() -> sqlite3.OperationalError:
    """The error SQLite itself raises on a full disk (SQLITE_FULL), provoked with max_page_count."""
    connection = sqlite3.connect(":memory:")
    connection.execute("CREATE TABLE t (x BLOB)")
    connection.execute("PRAGMA max_page_count = 2")
    try:
        connection.execute("INSERT INTO t VALUES (zeroblob(100000))")
    except sqlite3.OperationalError as error:
        return error
    finally:
        connection.close()
    raise AssertionError("max_page_count did not fill the database")


class PostgresDiskFull(Exception):
    """Stands for psycopg.errors.DiskFull (not installed here): what we read of it is its SQLSTATE."""

    sqlstate = "53100"


def test_every_kind_of_full_disk_is_recognised():
    sqlite_full = _sqlite_full_error()
    assert sqlite_full.sqlite_errorname == "SQLITE_FULL" and "database or disk is full" in str(sqlite_full)
    full = [
        sqlite_full,
        OperationalError("INSERT ...", {}, sqlite_full),  # as SQLAlchemy wraps it
        OSError(errno.ENOSPC, "No space left on device"),
        OSError(errno.EDQUOT, "Disk quota exceeded"),
        PostgresDiskFull("could not extend file: No space left on device"),
        OperationalError("INSERT ...", {}, PostgresDiskFull()),
        StorageFull("INSERT ...", {}, sqlite_full),
    ]
    chained = RuntimeError("while storing a run")
    chained.__cause__ = OSError(errno.ENOSPC, "No space left on device")
    full.append(chained)
    not_full = [
        sqlite3.OperationalError("database is locked"),
        OperationalError("INSERT ...", {}, sqlite3.OperationalError("database is locked")),
        IntegrityError("INSERT ...", {}, sqlite3.IntegrityError("UNIQUE constraint failed: run_tags.tag")),
        OSError(errno.EACCES, "Permission denied"),
        ValueError("disk"),
        None,
    ]
    assert [is_storage_full(error) for error in full] == [True] * len(full)
    assert [is_storage_full(error) for error in not_full] == [False] * len(not_full)


def test_a_write_on_a_full_database_raises_storage_full(tmp_path):
    """The engine turns the driver's error into StorageFull for every statement and commit; it is
    still an OperationalError (code that caught SQLAlchemy errors goes on catching it)."""
    engine = make_engine(sqlite_url(tmp_path))
    with engine.begin() as connection:
        connection.execute(text("CREATE TABLE t (x BLOB)"))

    @event.listens_for(engine, "connect")
    def _full(dbapi_connection, _record):
        (pages,) = dbapi_connection.execute("PRAGMA page_count").fetchone()
        dbapi_connection.execute(f"PRAGMA max_page_count = {pages}")

    engine.dispose()
    with pytest.raises(StorageFull) as raised, engine.begin() as connection:
        connection.execute(text("INSERT INTO t VALUES (zeroblob(100000))"))
    assert isinstance(raised.value, OperationalError) and str(raised.value) == FULL_MESSAGE
    assert isinstance(raised.value.orig, sqlite3.OperationalError)
    with engine.connect() as connection:  # reads go on
        assert connection.execute(text("SELECT count(*) FROM t")).scalar() == 0
    engine.dispose()


def _wal_size(tmp_path) -> int:
    wal = tmp_path / "parkourlab.sqlite3-wal"
    return wal.stat().st_size if wal.exists() else 0


def _grow_the_wal(engine, tmp_path, megabytes: int) -> int:
    """Write ``megabytes`` while a reader holds a snapshot (no checkpoint can finish under it), as
    a long export does; the WAL's size at its largest."""
    with engine.begin() as connection:
        connection.execute(text("CREATE TABLE IF NOT EXISTS t (x BLOB)"))
    reader = sqlite3.connect(tmp_path / "parkourlab.sqlite3", isolation_level=None)
    reader.execute("BEGIN")
    reader.execute("SELECT count(*) FROM t").fetchone()
    for _ in range(megabytes):
        with engine.begin() as connection:
            connection.execute(text("INSERT INTO t VALUES (randomblob(1048576))"))
            connection.execute(text("DELETE FROM t"))
    largest = _wal_size(tmp_path)
    reader.execute("COMMIT")
    reader.close()
    return largest


def test_the_wal_is_cut_back_after_a_checkpoint(tmp_path):
    engine = make_engine(sqlite_url(tmp_path))
    largest = _grow_the_wal(engine, tmp_path, 12)
    assert largest > 3 * JOURNAL_SIZE_LIMIT, "a reader kept every checkpoint from finishing"
    checkpoint(engine, "PASSIVE")  # what SQLite's automatic checkpoint does, or our own
    with engine.begin() as connection:  # the next write starts the WAL over, and cuts it to the limit
        connection.execute(text("INSERT INTO t VALUES (1)"))
    assert _wal_size(tmp_path) <= JOURNAL_SIZE_LIMIT < largest / 3
    assert checkpoint(engine, "TRUNCATE") == (0, 0, 0)
    assert _wal_size(tmp_path) == 0
    engine.dispose()


def test_without_the_limit_the_wal_keeps_its_largest_size(tmp_path):
    """The control: as before (no journal_size_limit), the same writes leave the WAL at its largest."""
    engine = make_engine(sqlite_url(tmp_path))
    event.listen(engine, "connect", lambda dbapi, _record: dbapi.execute("PRAGMA journal_size_limit=-1"))
    largest = _grow_the_wal(engine, tmp_path, 12)
    checkpoint(engine, "PASSIVE")
    with engine.begin() as connection:
        connection.execute(text("INSERT INTO t VALUES (1)"))
    assert _wal_size(tmp_path) == largest > 3 * JOURNAL_SIZE_LIMIT
    engine.dispose()


RUN = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.93, "ydot": -0.17}}
BIG_RUN = RunCreate.model_validate(RUN | {"jumps": 50, "trajectory_rate": 20})  # ~40 kB with its path


def _create_until_full(sessions, ids: list[int], limit: int = 10_000) -> int:
    for created in range(limit):
        try:
            with sessions() as session:
                ids.append(runs.create_run(session, BIG_RUN).id)
        except StorageFull:
            return created
    return limit


@pytest.mark.slow
def test_deletes_free_space_on_a_really_full_disk(tmp_path):
    """A 32 MB tmpfs holding a 14 MB file of something else, filled by the lab's own runs; then
    three rounds of: delete 5 runs (each delete goes through), store runs again until full (some
    fit, in the pages freed). The reserve is spent once, on the first delete's checkpoint, and
    never again: while the disk is full the database may not grow, so nothing piles up in the WAL
    that a later checkpoint would need disk for (without that cap the reserve shrank by 1.6 MB a
    round). Before, the first delete already failed (``database or disk is full``), and all after
    it. Then space returns (the other file deleted): the database grows, the reserve is whole."""
    with tmpfs(tmp_path / "disk", "32m") as disk:
        other = disk / "other"
        other.write_bytes(b"\0" * (14 * 2**20))
        engine = make_engine(sqlite_url(disk))
        migrate(engine)
        assert ensure_reserve(engine) == RESERVE_BYTES
        sessions = session_factory(engine)
        ids: list[int] = []
        assert _create_until_full(sessions, ids) > 100
        assert free_bytes(disk) == 0
        reserves = []
        for _round in range(3):
            for _ in range(5):
                with sessions() as session:
                    runs.delete(session, ids.pop(0))
            assert _create_until_full(sessions, ids) >= 2, "new runs fit in the pages the deletes freed"
            reserves.append(reserve_file(engine).stat().st_size)
        assert RESERVE_BYTES / 2 < reserves[0] == reserves[1] == reserves[2] < RESERVE_BYTES
        with sessions() as session:  # reads never stopped
            assert len(runs.list_runs(session, run_store.RunFilter(), limit=500, cursor=None)[0]) == len(ids)
        other.unlink()  # the operator frees space
        assert _create_until_full(sessions, ids, limit=20) == 20
        assert reserve_file(engine).stat().st_size == RESERVE_BYTES
        engine.dispose()


@pytest.mark.slow
def test_a_delete_on_a_full_disk_without_the_reserve_fails_clearly(tmp_path):
    """Filled by another file (the WAL still short of a checkpoint, everything new beyond the
    database file): with no reserve to give, a delete cannot go through either — a StorageFull
    saying so, not a bare 500; with the reserve it goes through (the test above)."""
    with tmpfs(tmp_path / "disk", "8m") as disk:
        engine = make_engine(sqlite_url(disk))
        migrate(engine)
        sessions = session_factory(engine)
        ids: list[int] = []
        assert _create_until_full(sessions, ids, limit=20) == 20
        ballast = fill(disk)
        assert _create_until_full(sessions, ids) == 0
        with pytest.raises(StorageFull, match="delete runs"), sessions() as session:
            runs.delete(session, ids[0])
        ballast.unlink()
        with sessions() as session:
            runs.delete(session, ids[0])
        engine.dispose()


def test_the_reserve_is_only_made_where_there_is_room(tmp_path, monkeypatch):
    engine = make_engine(sqlite_url(tmp_path))
    path = reserve_file(engine)
    assert path == tmp_path / "parkourlab.sqlite3-reserve"
    monkeypatch.setattr(database, "free_bytes", lambda _path: RESERVE_BYTES)  # room for it, not for a WAL besides
    assert ensure_reserve(engine) == RESERVE_BYTES - JOURNAL_SIZE_LIMIT
    assert path.stat().st_size == RESERVE_BYTES - JOURNAL_SIZE_LIMIT
    monkeypatch.setattr(database, "free_bytes", lambda _path: 0)
    assert ensure_reserve(engine) == RESERVE_BYTES - JOURNAL_SIZE_LIMIT, "kept, not grown"
    monkeypatch.undo()
    assert ensure_reserve(engine) == RESERVE_BYTES == path.stat().st_size
    assert database.release_reserve(engine) and not path.exists()
    assert reserve_file(make_engine("sqlite://")) is None, "a database in memory has no disk to fill"


def test_the_write_lock_serialises_two_sessions(tmp_path):
    """lock_for_write: a second session's lock waits until the first commits (SQLite BEGIN IMMEDIATE)."""
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    sessions = session_factory(engine)
    order = []
    with sessions() as first:
        database.lock_for_write(first)
        database.lock_for_write(first)  # again in the same transaction: a no-op

        def second():
            with sessions() as session:
                database.lock_for_write(session)
                order.append("second locked")

        thread = threading.Thread(target=second)
        thread.start()
        thread.join(0.3)
        order.append("first commits")
        first.commit()
    thread.join(10)
    assert order == ["first commits", "second locked"]
    engine.dispose()
