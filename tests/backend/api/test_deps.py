"""What routes ask FastAPI for (backend/api/deps.py): the store's one thread hop per route with a
session of its own, the run filters as one query, the 3D view or a 503 saying why, the token check."""

import asyncio
import threading
from types import SimpleNamespace

import pytest
from fastapi import HTTPException
from sqlalchemy import text

from backend.api import deps
from backend.api.deps import AUTHORIZED, VIEW_NOT_STARTED, Database, run_filter, view_of
from backend.api.security import require_token
from backend.repositories.runs import RunFilter
from backend.schemas import RunKind, RunStatus
from backend.store.database import StorageFull


@pytest.fixture
def database_url():
    return None  # SQLite: nothing here depends on the database


def test_a_routes_database_work_runs_in_a_request_thread_with_a_session_of_its_own(sessions):
    db = Database(sessions)
    seen = []

    def work(session, value, *, times):
        seen.append((threading.get_ident(), session))
        return session.execute(text("SELECT :v"), {"v": value}).scalar_one() * times

    assert asyncio.run(db(work, 21, times=2)) == 42
    assert asyncio.run(db(work, 1, times=1)) == 1
    (first_thread, first), (_, second) = seen
    assert first_thread != threading.get_ident(), "not on the event loop"
    assert first is not second, "each call opens a session, and closes it"


def test_a_full_disk_rolls_back_then_folds_the_wal_and_is_raised(sessions, monkeypatch):
    folded = []
    monkeypatch.setattr(deps, "after_storage_full", lambda engine: folded.append((engine, held.in_transaction())))
    held = None

    def fills_the_disk(session):
        nonlocal held
        held = session
        session.execute(text("SELECT 1"))  # a transaction under way
        raise StorageFull("INSERT ...", {}, OSError("No space left on device"))

    with pytest.raises(StorageFull):
        Database(sessions).run(fills_the_disk)
    assert folded == [(sessions.kw["bind"], False)], "the WAL folded once, after the rollback"


def test_the_run_filters_are_one_query_with_status_by_its_name():
    where = asyncio.run(run_filter(kind=RunKind.ROBOT, status_=RunStatus.DONE, zeta0_min=0.85, tag="live"))
    assert where == RunFilter(kind="robot", status="done", zeta0_min=0.85, tag="live")
    assert asyncio.run(run_filter()) == RunFilter(), "no filter: every run"


@pytest.mark.parametrize(
    ("query", "field"),
    [
        ("status=gone", "status"),
        ("zeta0_min=1.5", "zeta0_min"),
        ("psi0_max=nan", "psi0_max"),
        ("experiment_id=0", "experiment_id"),
    ],
)
def test_a_run_filter_out_of_range_is_a_422_naming_it(client, query, field):
    response = client.get(f"/api/v1/runs?{query}")
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["query", field]


def _request(view_starter) -> SimpleNamespace:
    return SimpleNamespace(app=SimpleNamespace(state=SimpleNamespace(view_starter=view_starter)))


def test_the_view_or_a_503_saying_why_there_is_none():
    view = object()
    assert view_of(_request(SimpleNamespace(view=view, unavailable_reason="unused"))) is view
    for starter, reason in (
        (None, VIEW_NOT_STARTED),
        (SimpleNamespace(view=None, unavailable_reason="the 3D view is starting"), "the 3D view is starting"),
    ):
        with pytest.raises(HTTPException) as raised:
            view_of(_request(starter))
        assert (raised.value.status_code, raised.value.detail) == (503, reason)


def test_authorized_routes_declare_the_token_check_the_middleware_looks_for():
    """TokenFirst leaves open exactly the mutating routes that do not declare ``require_token``."""
    assert [dependency.dependency for dependency in AUTHORIZED] == [require_token]
