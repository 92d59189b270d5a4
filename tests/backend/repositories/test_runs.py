"""The runs repository's pages (backend/repositories/runs.py), on SQLite and PostgreSQL, against a plain
Python reference: every filter and sort, walked page by page, gives the same runs in the same order
with the same tags and the same total; the total follows every change of the store; a new run's
outcome columns come from its results."""

import datetime
import random

import pytest
from sqlalchemy import insert

from backend.repositories.run_list_cache import store_stamp
from backend.repositories.runs import SORTS, RunFilter, add_run, listed_page, matching_count, outcome_columns
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Experiment, Run, RunTag
from backend.store.run_record import RunRecord

TAGS = ["fig8", "fig11", "robot-a", "pid", "zeta:0.9", "a/b", "größe", "slip-test"]  # what a Label allows
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
    "status": (RunFilter(status="failed"), lambda run: run["status"] == "failed"),
    "end reason": (RunFilter(end_reason="e-stop"), lambda run: run["end_reason"] == "e-stop"),
    "end reason's kind": (
        RunFilter(end_reason="error"),
        lambda run: (run["end_reason"] or "").split(":")[0] == "error",
    ),
    "closed loop, pid": (
        RunFilter(loop="closed", controller="pid"),
        lambda run: run["loop"] == "closed" and run["controller"] == "pid",
    ),
    "search": (
        RunFilter(q="SLIP"),
        lambda run: "slip" in run["notes"].lower() or any("slip" in tag for tag in run["tags"]),
    ),
    "search a tag": (RunFilter(q="ZETA:0"), lambda run: any("zeta:0" in tag for tag in run["tags"])),
    "search with a wildcard": (RunFilter(q="100%"), lambda run: "100%" in run["notes"]),
}
ENDINGS = [None, "jumps done", "stopped", "e-stop", "link lost", "robot disarmed (fell or timed out)",
           "error: the link timed out", "error", "errors are not one"]  # fmt: skip
NOTES = ["", "Left foot slipped on jump 3", "100% dry", "1000 dry", "wet wall", "slipped? no"]


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
            "created_at": start + datetime.timedelta(seconds=rng.randrange(100_000)),
            "duration_s": rng.choice([0.1, 0.2, 0.3]),  # ties: the sort falls back on the id
            "code_version": "test",
            "model": {"alpha": 77.6},
            "controls": [[rng.uniform(15, 45), rng.uniform(0.8, 0.98)]],
            "start_state": [-0.93, -0.17],
            "jumps": 20,
            "alpha": 77.6,
            "failure_code": rng.choice([None, "slip", "no_flight"]),
            "climb": round(rng.uniform(-1, 8), 1),
            "results": {},
            "status": rng.choice(["done", "done", "failed"]),
            "end_reason": rng.choice(ENDINGS),
            "notes": rng.choice(NOTES),
            "target": rng.choice([None, None, 0.4, 0.55]),
            "jumps_completed": rng.randrange(21),
        }
        run |= {"loop": "open" if run["target"] is None else "closed", "controller": run["target"] and "pid"}
        run["psi0_deg"], run["zeta0"] = run["controls"][0]
        run_tags = sorted(rng.sample(TAGS, rng.randrange(5)))
        tags += [{"run_id": run_id, "tag": tag} for tag in run_tags]
        runs.append(run | {"tags": run_tags})
    with engine.begin() as connection:
        connection.execute(insert(Run), [{k: v for k, v in run.items() if k != "tags"} for run in runs])
        connection.execute(insert(RunTag), tags)
        if connection.dialect.name == "postgresql":  # the ids were given: new runs' come after them
            connection.exec_driver_sql("SELECT setval('runs_id_seq', (SELECT max(id) FROM runs))")
    yield session_factory(engine), runs
    engine.dispose()


def _walk(session, where: RunFilter, sort: str, limit: int, *, by_offset: bool = False) -> list[dict]:
    """Every page of ``where`` in ``sort`` order, following each page's cursor or offset (or, with
    ``by_offset``, asking each page by its offset, as the panel does); every page's total the same."""
    rows, cursor, offset, totals = [], None, 0, set()
    while True:
        page, following, total = listed_page(session, where, limit=limit, cursor=cursor, sort=sort, offset=offset)
        assert len(page) <= limit
        rows += page
        totals.add(total)
        if following is None:
            assert totals == {len(rows)}, "every page gives the number of runs that match"
            return rows
        if by_offset:
            offset += limit
        else:
            cursor, offset = (following, 0) if sort.lstrip("-") == "id" else (None, following)


def _reference_order(runs, sort):
    """``runs`` in ``sort`` order: the column (None the smallest), then the id the same way."""
    name = sort.lstrip("-")
    key = (lambda run: run["id"]) if name == "id" else (lambda run: (run[name] is not None, run[name] or 0, run["id"]))
    return sorted(runs, key=key, reverse=sort.startswith("-"))


@pytest.mark.parametrize("sort", SORTS)
def test_pages_list_each_matching_run_once_in_order_with_its_tags(stored, sort):
    sessions, runs = stored
    with sessions() as session:
        for label, (where, matches) in FILTERS.items():
            expected = _reference_order([run for run in runs if matches(run)], sort)
            assert expected or label.startswith("search with"), f"{label}: the reference matches some runs"
            listed = _walk(session, where, sort, limit=17)
            assert [row["id"] for row in listed] == [run["id"] for run in expected], label
            assert [row["tags"] for row in listed] == [run["tags"] for run in expected], label
            assert all(row["controls"] == run["controls"] for row, run in zip(listed, expected, strict=True))
            for name in ("end_reason", "loop", "controller", "target", "notes", "status"):
                assert [row[name] for row in listed] == [run[name] for run in expected], (label, name)


@pytest.mark.parametrize("sort", ["-id", "id", "-climb", "end_reason"])
def test_any_page_can_be_asked_for_by_offset(stored, sort):
    """The panel jumps to a page by its offset, whatever the sort (id sorts too, without a cursor)."""
    sessions, runs = stored
    with sessions() as session:
        listed = _walk(session, RunFilter(), sort, limit=23, by_offset=True)
    assert [row["id"] for row in listed] == [run["id"] for run in _reference_order(runs, sort)]


def test_a_page_of_an_empty_filter_is_empty(stored):
    sessions, _ = stored
    with sessions() as session:
        assert listed_page(session, RunFilter(tag="nobody"), limit=50, cursor=None) == ([], None, 0)


def _record(**changes) -> RunRecord:
    fields = dict(kind="sim", status="done", model={"alpha": 77.6}, controls=[[30.0, 0.9]], start_state=[-0.9, -0.2],
                  jumps=4, jumps_completed=4, climb=1.0, results={}, code_version="test", tags=("fresh",))  # fmt: skip
    return RunRecord(**(fields | changes))


def test_the_total_follows_every_change_of_the_store(stored):
    """A counted total is kept while nothing changes (SQLite) and counted again after a run is
    added or deleted, by another connection or by this one, and after a rollback."""
    sessions, runs = stored
    fresh = RunFilter(tag="fresh")
    with sessions() as reader:
        assert matching_count(reader, RunFilter()) == len(runs)
        assert matching_count(reader, fresh) == 0
        reader.commit()
        with sessions() as writer:  # another connection
            add_run(writer, _record())
            writer.commit()
        assert matching_count(reader, RunFilter()) == len(runs) + 1
        assert matching_count(reader, fresh) == 1
        added = add_run(reader, _record())  # this connection, in a transaction
        reader.flush()
        assert matching_count(reader, fresh) == 2
        reader.rollback()
        assert matching_count(reader, fresh) == 1, "the rolled-back run is not counted"
        reader.execute(Run.__table__.delete().where(Run.id == runs[0]["id"]))
        reader.commit()
        assert matching_count(reader, RunFilter()) == len(runs)
        assert added.id is None or reader.get(Run, added.id) is None


def test_a_new_runs_outcome_columns_come_from_its_results(stored):
    sessions, _ = stored
    closed = {"target_m": 0.55, "kp": 0.04, "ki": 0.0, "kd": 0.02}
    robot_results = {"end_reason": "e-stop", "closed_loop": closed, "touchdowns": [{}, {}, {}]}
    assert outcome_columns("robot", robot_results) == {
        "end_reason": "e-stop", "loop": "closed", "controller": "pid", "target": 0.55, "touchdowns": 3}  # fmt: skip
    assert outcome_columns("robot", {"end_reason": None, "closed_loop": None}) == {
        "end_reason": None, "loop": "open", "controller": None, "target": None, "touchdowns": 0}  # fmt: skip
    replay = outcome_columns("replay", {"source_run_id": 4, "closed_loop": closed, "touchdowns": [{}]})
    assert replay == {"end_reason": None, "loop": "closed", "controller": "pid", "target": 0.55, "touchdowns": 1}
    assert outcome_columns("sim", {"failure": None, "end_reason": "nonsense"}) == {
        "end_reason": None, "loop": "open", "controller": None, "target": None, "touchdowns": None}  # fmt: skip
    assert outcome_columns("robot", {"end_reason": "error: " + "x" * 500})["end_reason"] == "error: " + "x" * 193
    with sessions() as session:
        run = add_run(session, _record(kind="robot", results=robot_results))
        session.commit()
        stored_run = session.get(Run, run.id)
        assert (stored_run.end_reason, stored_run.loop, stored_run.controller, stored_run.target) == (
            "e-stop", "closed", "pid", 0.55)  # fmt: skip
        assert matching_count(session, RunFilter(end_reason="e-stop", loop="closed")) >= 1


def test_a_kept_order_serves_pages_until_a_run_changes(stored, database_url):
    """SQLite: a filtered page is cut from the order kept on the connection; a new or retagged run
    (another connection's) is in the next page at once; a commit that changes no run (a new
    experiment, a job's trials) keeps the order."""
    sessions, _ = stored
    where = RunFilter(kind="sim")
    with sessions() as reader:
        first, _, total = listed_page(reader, where, limit=5, cursor=None, sort="-climb")
        reader.commit()
        stamp = store_stamp(reader.connection())
        with sessions() as writer:
            writer.add(Experiment(name="unrelated"))
            writer.commit()
        assert store_stamp(reader.connection()) == stamp, "no run changed"
        assert listed_page(reader, where, limit=5, cursor=None, sort="-climb")[0] == first
        with sessions() as writer:  # a live run's journal writer: its duration, twice a second
            writer.execute(Run.__table__.update().where(Run.id == first[0]["id"]).values(duration_s=99.0))
            writer.commit()
        assert store_stamp(reader.connection()) == stamp, "a duration alone is no change a list sees"
        with sessions() as writer:
            best = add_run(writer, _record(climb=100.0))
            writer.commit()
            best_id = best.id
        reader.commit()
        if database_url is None or database_url.startswith("sqlite"):
            assert store_stamp(reader.connection()) != stamp
        again, _, again_total = listed_page(reader, where, limit=5, cursor=None, sort="-climb")
        assert [row["id"] for row in again] == [best_id] + [row["id"] for row in first[:4]]
        assert again_total == total + 1
        with sessions() as writer:
            writer.execute(RunTag.__table__.insert().values(run_id=first[2]["id"], tag="late"))
            writer.commit()
        reader.commit()
        tagged, _, _ = listed_page(reader, RunFilter(tag="late"), limit=5, cursor=None, sort="-climb")
        assert [row["id"] for row in tagged] == [first[2]["id"]]
        listed = listed_page(reader, where, limit=5, cursor=None, sort="-climb")[0]
        assert listed[3]["tags"] == sorted([*first[2]["tags"], "late"])
        with sessions() as writer:  # what a list filters by: the run leaves the sims
            writer.execute(Run.__table__.update().where(Run.id == best_id).values(kind="robot"))
            writer.commit()
        reader.commit()
        assert listed_page(reader, where, limit=5, cursor=None, sort="-climb")[0][0]["id"] == first[0]["id"]
