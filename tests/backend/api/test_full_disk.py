"""The API on a full disk (issue 14): writes answer 507 with what to do, deletes still work.

Before: every write on a full disk was a bare text 500 (``Internal Server Error``), and on a real
full filesystem DELETE failed too (``database or disk is full``), so there was no way to free
space through the service. Now writes answer **507** JSON — "the disk holding the database is
full: free space (e.g. delete runs) and retry" — reads go on, DELETE answers 204, new records fit
in the space the deletes freed, and everything resumes when space returns.

Two ways to fill the disk: SQLite's ``max_page_count`` (SQLITE_FULL exactly as a full disk gives,
no root needed; statvfs made to say 0 bytes free to match), and a real 32 MB tmpfs (root only).
"""

import contextlib
import sqlite3
import time

import pytest
from fastapi.testclient import TestClient
from sqlalchemy import event

from backend.api.app import create_app
from backend.settings import Settings
from backend.store import database
from backend.store.database import FULL_MESSAGE
from tests.backend.api.bodies import RUN
from tests.backend.disk import fill, tmpfs

DESCRIPTION = "d" * 10_000


@pytest.fixture
def database_url():
    """SQLite only: both ways of filling the disk are SQLite's file (PostgreSQL's disk-full error is
    mapped to the same 507 by ``is_storage_full``, tested in tests/backend/store/test_storage.py)."""
    return None


def _runs(client, auth, count: int) -> list[int]:
    return [client.post("/api/v1/runs", json=RUN | {"jumps": 2}, headers=auth).json()["id"] for _ in range(count)]


def _fill(client, auth) -> None:
    """Store records until the disk is full: big experiments, then small ones, then runs, each
    until a 507 (a small record can fit where a big one no longer does)."""
    bodies = [
        ("/api/v1/experiments", {"name": "ballast", "description": DESCRIPTION}),
        ("/api/v1/experiments", {"name": "ballast"}),
        ("/api/v1/runs", RUN | {"jumps": 2}),
    ]
    for path, body in bodies:
        for _ in range(10_000):
            response = client.post(path, json=body, headers=auth)
            if response.status_code == 507:
                break
            assert response.status_code == 201, response.text
        else:
            raise AssertionError("the disk never filled")


def _is_full_answer(response) -> bool:
    return (
        response.status_code == 507
        and response.headers["content-type"] == "application/json"
        and response.json() == {"detail": FULL_MESSAGE}
    )


@pytest.fixture
def full(client, monkeypatch):
    """The database capped at its current size (SQLITE_FULL on any growth) and statvfs saying the
    disk is full; undo() is space returning."""
    engine = client.app.state.sessions.kw["bind"]
    with engine.connect() as connection:
        pages = connection.exec_driver_sql("PRAGMA page_count").scalar()

    def cap(dbapi_connection, _record):
        dbapi_connection.execute(f"PRAGMA max_page_count = {pages}")

    event.listen(engine, "connect", cap)
    engine.dispose()  # every connection from now on is capped
    monkeypatch.setattr(database, "free_bytes", lambda _path: 0)
    yield monkeypatch
    event.remove(engine, "connect", cap)


def test_writes_answer_507_and_deletes_free_space(client, auth, full):
    runs = _runs(client, auth, 4)  # stored in the pages the database already had
    _fill(client, auth)
    assert _is_full_answer(client.post("/api/v1/runs", json=RUN, headers=auth))
    assert _is_full_answer(
        client.post("/api/v1/experiments", json={"name": "x", "description": DESCRIPTION}, headers=auth)
    )
    assert _is_full_answer(client.patch(f"/api/v1/runs/{runs[0]}", json={"notes": "n" * 100_000}, headers=auth))
    assert client.get("/api/v1/runs").status_code == 200, "reads go on"
    for run in runs[:3]:
        assert client.delete(f"/api/v1/runs/{run}", headers=auth).status_code == 204
    assert client.get(f"/api/v1/runs/{runs[0]}").status_code == 404
    assert client.post("/api/v1/runs", json=RUN | {"jumps": 2}, headers=auth).status_code == 201, "fits where runs were"
    full.undo()  # space returns
    assert [client.post("/api/v1/runs", json=RUN, headers=auth).status_code for _ in range(5)] == [201] * 5
    assert (
        client.post("/api/v1/experiments", json={"name": "x", "description": DESCRIPTION}, headers=auth).status_code
        == 201
    )


@pytest.mark.slow
def test_the_api_on_a_really_full_disk(tmp_path):
    """The service's data directory on a 32 MB tmpfs that another file fills (root only)."""
    with tmpfs(tmp_path / "disk", "32m") as disk:
        settings = Settings.from_environment(disk / "data")
        with TestClient(create_app(settings)) as client:
            auth = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
            runs = _runs(client, auth, 20)
            experiment = client.post("/api/v1/experiments", json={"name": "e"}, headers=auth).json()["id"]
            ballast = fill(disk)
            answers = [client.post("/api/v1/runs", json=RUN, headers=auth) for _ in range(3)]
            assert all(_is_full_answer(answer) for answer in answers), [answer.text for answer in answers]
            assert _is_full_answer(client.patch(f"/api/v1/runs/{runs[0]}", json={"notes": "n" * 100_000}, headers=auth))
            assert client.get(f"/api/v1/runs/{runs[0]}").status_code == 200
            assert [client.delete(f"/api/v1/runs/{run}", headers=auth).status_code for run in runs[:5]] == [204] * 5
            assert client.delete(f"/api/v1/experiments/{experiment}", headers=auth).status_code == 204
            assert client.post("/api/v1/runs", json=RUN | {"jumps": 2}, headers=auth).status_code == 201
            ballast.unlink()
            assert [client.post("/api/v1/runs", json=RUN, headers=auth).status_code for _ in range(5)] == [201] * 5


JOB = {"zeta0s": [0.9], "trials": 16, "cap": 60, "guess": {"xdot": -0.93, "ydot": -0.2}, "seed": 5}


@pytest.mark.slow
@pytest.mark.parametrize("killed", [True, False], ids=["killed", "stopped"])
def test_a_crash_on_a_full_disk_does_not_block_the_way_out(tmp_path, compute, killed):
    """Issue 26: killed during a job on a full disk, the service failed to start again ("Application
    startup failed": requeueing the job committed into the full disk), so DELETE — the documented way
    to free space — could not be reached. Now it starts, says what waits, reads and deletes, and the
    job goes on once there is room. Stopped cleanly instead, SQLite had removed the WAL and its
    shared memory, which a full disk cannot give again: the space reserve makes room for them."""
    with tmpfs(tmp_path / "disk", "32m") as disk:
        settings = Settings.from_environment(disk / "data")
        with TestClient(create_app(settings, compute=compute, run_jobs=False)) as client:
            auth = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
            runs = _runs(client, auth, 10)
            job = client.post("/api/v1/jobs", json=JOB, headers=auth).json()["id"]
            engine = client.app.state.sessions.kw["bind"]
        with engine.begin() as connection:  # as the process left it when killed mid-job
            connection.exec_driver_sql(f"UPDATE jobs SET state = 'running' WHERE id = {job}")
        engine.dispose()
        # A killed process leaves its WAL and shared-memory files behind (a clean close removes them).
        left_open = sqlite3.connect(settings.data_dir / "parkourlab.sqlite3" if killed else ":memory:")
        left_open.execute("SELECT 1").fetchone()
        ballast = fill(disk)
        with contextlib.closing(left_open), TestClient(create_app(settings, compute=compute)) as client:
            assert client.get("/api/v1/health").status_code == 200
            assert client.get(f"/api/v1/runs/{runs[0]}").status_code == 200
            assert [client.delete(f"/api/v1/runs/{run}", headers=auth).status_code for run in runs[:3]] == [204] * 3
            ballast.unlink()
            deadline = time.monotonic() + 120
            while (state := client.get(f"/api/v1/jobs/{job}").json()["state"]) != "done":
                assert time.monotonic() < deadline, state
                time.sleep(0.2)
            assert state == "done"
            assert client.get(f"/api/v1/jobs/{job}").json()["completed"] == JOB["trials"]
            assert client.get("/api/v1/health").json()["notices"] == []


def test_start_up_goes_on_while_what_a_crash_left_waits_for_space(settings, compute, monkeypatch):
    """Whether settling a crash's leftovers finds the disk full depends on the WAL's slack; here
    every such write fails until space "returns": the service starts, answers, says what waits,
    and settles them once it fits."""
    from backend.repositories import jobs as stored_jobs
    from backend.services import robot, storage_waits
    from backend.store.database import StorageFull

    monkeypatch.setattr(storage_waits, "STORAGE_RETRY", 0.05)
    disk_full = [True]

    def failing_while_full(write):
        def attempt(*args, **kwargs):
            if disk_full[0]:
                raise StorageFull("UPDATE jobs", {}, Exception("database or disk is full"))
            return write(*args, **kwargs)

        return attempt

    with TestClient(create_app(settings, compute=compute, run_jobs=False)) as client:
        auth = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
        job = client.post("/api/v1/jobs", json=JOB, headers=auth).json()["id"]
    monkeypatch.setattr(stored_jobs, "recover_interrupted", failing_while_full(stored_jobs.recover_interrupted))
    monkeypatch.setattr(robot, "recover_interrupted", failing_while_full(robot.recover_interrupted))
    with TestClient(create_app(settings, compute=compute)) as client:
        notices = client.get("/api/v1/health").json()["notices"]
        assert len(notices) == 2 and all(
            notice.startswith("the disk holding the database is full") for notice in notices
        )
        assert client.get(f"/api/v1/jobs/{job}").json()["state"] == "queued", "nothing ran before its turn"
        disk_full[0] = False
        deadline = time.monotonic() + 60
        while (state := client.get(f"/api/v1/jobs/{job}").json()["state"]) != "done":
            assert time.monotonic() < deadline, state
            time.sleep(0.1)
        assert client.get("/api/v1/health").json()["notices"] == []
