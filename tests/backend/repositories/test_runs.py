"""The runs repository's pages (backend/repositories/runs.py), on SQLite and PostgreSQL, against a plain
Python reference: every filter and sort, walked page by page, gives the same runs in the same order
with the same tags."""

import datetime
import random

import pytest
from sqlalchemy import insert

from backend.repositories.runs import SORTS, RunFilter, listed_page
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Run, RunTag

TAGS = ["fig8", "fig11", "robot-a", "pid", "zeta:0.9", "a/b", "größe"]  # what a Label allows
FILTERS = {
    "none": (RunFilter(), lambda run: True),
    "zeta0 range": (RunFilter(zeta0_min=0.85, zeta0_max=0.9), lambda run: 0.85 <= run["zeta0"] <= 0.9),
    "tag": (RunFilter(tag="fig8"), lambda run: "fig8" in run["tags"]),
    "two ranges": (
        RunFilter(psi0_min=25, psi0_max=35, zeta0_min=0.9),
        lambda run: 25 <= run["psi0_deg"] <= 35 and run["zeta0"] >= 0.9,
    ),
    "kind and failure": (
        RunFilter(kind="sim", failure_code="slip"),
        lambda run: run["kind"] == "sim" and run["failure_code"] == "slip",
    ),
}


@pytest.fixture
def stored(database_url, tmp_path):
    """Sessions on a store of 240 runs with 0 to 4 tags each (random, seeded), and the runs as the
    reference sees them."""
    engine = make_engine(database_url or sqlite_url(tmp_path))
    migrate(engine)
    rng, runs, tags = random.Random(3), [], []
    start = datetime.datetime(2026, 1, 1, tzinfo=datetime.UTC)
    for run_id in range(1, 241):
        run = {
            "id": run_id,
            "kind": rng.choice(["sim", "sim", "robot"]),
            "status": "done",
            "created_at": start + datetime.timedelta(seconds=rng.randrange(100_000)),
            "duration_s": rng.choice([0.1, 0.2, 0.3]),  # ties: the sort falls back on the id
            "code_version": "test",
            "model": {"alpha": 77.6},
            "controls": [[rng.uniform(15, 45), rng.uniform(0.8, 0.98)]],
            "start_state": [-0.93, -0.17],
            "jumps": 20,
            "alpha": 77.6,
            "failure_code": rng.choice([None, "slip", "no_flight"]),
            "jumps_completed": 20,
            "climb": round(rng.uniform(-1, 8), 1),
            "results": {},
        }
        run["psi0_deg"], run["zeta0"] = run["controls"][0]
        run_tags = sorted(rng.sample(TAGS, rng.randrange(5)))
        tags += [{"run_id": run_id, "tag": tag} for tag in run_tags]
        runs.append(run | {"tags": run_tags})
    with engine.begin() as connection:
        connection.execute(insert(Run), [{k: v for k, v in run.items() if k != "tags"} for run in runs])
        connection.execute(insert(RunTag), tags)
    yield session_factory(engine), runs
    engine.dispose()


def _walk(session, where: RunFilter, sort: str, limit: int) -> list[dict]:
    """Every page of ``where`` in ``sort`` order, following each page's cursor or offset."""
    rows, cursor, offset = [], None, 0
    while True:
        page, following = listed_page(session, where, limit=limit, cursor=cursor, sort=sort, offset=offset)
        assert len(page) <= limit
        rows += page
        if following is None:
            return rows
        cursor, offset = (following, 0) if sort.lstrip("-") == "id" else (None, following)


@pytest.mark.parametrize("sort", SORTS)
def test_pages_list_each_matching_run_once_in_order_with_its_tags(stored, sort):
    sessions, runs = stored
    name, descending = sort.lstrip("-"), sort.startswith("-")
    with sessions() as session:
        for label, (where, matches) in FILTERS.items():
            expected = sorted(
                (run for run in runs if matches(run)),
                key=lambda run: (run[name], run["id"]),
                reverse=descending,
            )
            listed = _walk(session, where, sort, limit=17)
            assert [row["id"] for row in listed] == [run["id"] for run in expected], label
            assert [row["tags"] for row in listed] == [run["tags"] for run in expected], label
            assert all(row["controls"] == run["controls"] for row, run in zip(listed, expected, strict=True))


def test_a_page_of_an_empty_filter_is_empty(stored):
    sessions, _ = stored
    with sessions() as session:
        assert listed_page(session, RunFilter(tag="nobody"), limit=50, cursor=None) == ([], None)
