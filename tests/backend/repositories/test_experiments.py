"""The experiments' SQL (backend/repositories/experiments.py) on a migrated SQLite file: a page of
experiments with their run counts in one query, and what an experiment still holds."""

import pytest
from sqlalchemy import event

from backend.errors import NotFound
from backend.repositories import experiments as stored
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Job, Run


@pytest.fixture
def engine(tmp_path):
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    yield engine
    engine.dispose()


@pytest.fixture
def session(engine):
    with session_factory(engine)() as session:
        yield session


def _run(experiment_id: int | None) -> Run:
    return Run(experiment_id=experiment_id, kind="sim", status="done", code_version="test", model={}, controls=[],
               start_state=[], jumps=1, alpha=1.0, psi0_deg=30.0, zeta0=0.9, jumps_completed=1, climb=0.0,
               results={})  # fmt: skip


def test_a_page_counts_each_experiments_runs_in_one_query(engine, session):
    made = [stored.add(session, name=f"e{i}") for i in range(4)]
    session.flush()
    for experiment, runs in zip(made, (0, 3, 1, 2), strict=True):
        session.add_all([_run(experiment.id) for _ in range(runs)])
    session.add(_run(None))
    session.commit()
    statements = []
    event.listen(engine, "before_cursor_execute", lambda *args: statements.append(args[2]))
    rows, cursor = stored.counted_page(session, limit=3, cursor=None)
    assert len(statements) == 1, statements
    assert [(experiment.name, runs) for experiment, runs in rows] == [("e3", 2), ("e2", 1), ("e1", 3)]
    assert cursor == made[1].id
    rest, end = stored.counted_page(session, limit=3, cursor=cursor)
    assert [(experiment.name, runs) for experiment, runs in rest] == [("e0", 0)] and end is None


def test_run_and_job_counts_and_delete(session):
    experiment = stored.add(session, name="studies")
    session.flush()
    session.add(_run(experiment.id))
    session.add(Job(kind="mjtf", spec={}, state="queued", total=1, code_version="test", experiment_id=experiment.id))
    session.commit()
    assert (stored.run_count(session, experiment.id), stored.job_count(session, experiment.id)) == (1, 1)
    assert stored.locked_experiment(session, experiment.id) is experiment
    other = stored.add(session, name="empty")
    session.commit()
    stored.delete(session, other)
    session.commit()
    with pytest.raises(NotFound, match=f"experiment {other.id} does not exist"):
        stored.get(session, other.id)
