"""What a connection keeps of the run list (backend/repositories/run_list_cache.py): totals that
stay right through every kind of change another connection makes, bases that survive the writes
that only add runs, the count since a base read through the id's range, and the cache's bounds."""

import random
from array import array

import pytest
from sqlalchemy import delete, func, select, update

from backend.repositories import run_list_cache
from backend.repositories.run_filters import RunFilter, filtered
from backend.repositories.run_list_cache import ListCache, Stamp, _count_statement, list_cache, matching_count
from backend.repositories.runs import _sort_order, add_run, listed_page, relabel
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from backend.store.models import Run, RunTag
from backend.store.run_record import RunRecord

TAGS = ["a", "b", "slip-test", "c"]
SORTS = ("-id", "id", "-climb", "zeta0", "status", "-end_reason", "end_reason")
FILTERS = [RunFilter(), RunFilter(tag="a"), RunFilter(kind="robot"), RunFilter(q="slip"), RunFilter(status="failed"),
           RunFilter(zeta0_min=0.85, zeta0_max=0.92), RunFilter(kind="sim", tag="b"),
           RunFilter(q="SLIP", kind="sim")]  # fmt: skip
# Each change another connection makes, and whether it reshapes the runs (changes what runs older
# than the newest count towards a total): None where it is no change a list sees at all.
CHANGES = {
    "add a run": False,
    "edit the newest run": False,
    "retag the newest run": False,
    "edit an old run": True,
    "retag an old run": True,
    "untag an old run": True,
    "delete the newest run": True,
    "delete an old run": True,
    "a duration alone": None,
}


def _record(rng: random.Random) -> RunRecord:
    return RunRecord(kind=rng.choice(["sim", "robot"]), status=rng.choice(["done", "failed"]), duration_s=1.0,
                     code_version="test", model={"alpha": 77.6}, controls=[[30.0, rng.uniform(0.8, 0.98)]],
                     start_state=[-0.9, -0.2], jumps=4, jumps_completed=4, climb=round(rng.uniform(-1, 3), 1),
                     results=rng.choice([{}, {"end_reason": "e-stop"}, {"end_reason": "stopped"}]),
                     tags=tuple(rng.sample(TAGS, rng.randrange(3))))  # fmt: skip


def _change(writer, name: str, rng: random.Random) -> None:
    """One change of ``name`` (CHANGES), committed by ``writer``."""
    ids = writer.scalars(select(Run.id).order_by(Run.id)).all()
    newest, old = ids[-1], rng.choice(ids[:-1])
    if name == "add a run":
        add_run(writer, _record(rng)).notes = rng.choice(["", "slipped", "dry"])
    elif name == "edit the newest run":
        writer.execute(
            update(Run)
            .where(Run.id == newest)
            .values(kind="robot", notes="slip at 3", status="failed", climb=rng.uniform(-1, 3), zeta0=0.83)
        )
    elif name == "retag the newest run":  # tags other than its own: a relabel to the same tags changes nothing
        run = writer.get(Run, newest)
        relabel(run, next(tags for tags in iter(lambda: rng.sample(TAGS, 2), None) if set(tags) != set(run.tags)))
    elif name == "edit an old run":
        writer.execute(update(Run).where(Run.id == old).values(status="failed", notes="late slip", zeta0=0.9))
    elif name == "retag an old run":
        relabel(writer.get(Run, old), rng.sample(TAGS, 2))
    elif name == "untag an old run":
        run_id, tag = rng.choice(writer.execute(select(RunTag.run_id, RunTag.tag).where(RunTag.run_id < newest)).all())
        writer.execute(delete(RunTag).where(RunTag.run_id == run_id, RunTag.tag == tag))
    elif name == "delete the newest run":
        writer.execute(delete(Run).where(Run.id == newest))
    elif name == "delete an old run":
        writer.execute(delete(Run).where(Run.id == old))
    else:
        writer.execute(update(Run).where(Run.id == old).values(duration_s=rng.uniform(1, 9)))
    writer.commit()


@pytest.fixture
def sessions(database_url, tmp_path):
    engine = make_engine(database_url or sqlite_url(tmp_path))
    migrate(engine)
    yield session_factory(engine)
    engine.dispose()


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_totals_are_right_after_every_kind_of_change(sessions, seed):
    """A reader's totals, kept or counted since a base, equal a plain COUNT after each of 60 random
    changes by another connection, and its pages by id, cut from orders kept and brought up to
    date, the runs in order — by id and by other columns (nullable ones too), the runs added
    since an order was read put at their places; only the changes to older runs than the newest
    reshape the runs (SQLite), so the bases and the orders outlive the others."""
    rng = random.Random(seed)
    with sessions() as writer:
        for _ in range(30):
            add_run(writer, _record(rng)).notes = rng.choice(["", "slipped on 2", "wet"])
        writer.commit()
    with sessions() as reader, sessions() as writer, sessions() as reference:
        for step in range(60):
            name = rng.choice(list(CHANGES))
            before = list_cache(reader.connection())
            _change(writer, name, rng)
            reader.commit()
            for where in FILTERS:
                expected = reference.scalar(filtered(select(func.count()).select_from(Run), where))
                assert matching_count(reader, where) == expected, (step, name, where)
                assert matching_count(reader, where) == expected, "the same again, kept"
                for sort in SORTS:
                    ordered = filtered(select(Run.id), where).order_by(*_sort_order(sort))
                    expected_ids = reference.scalars(ordered).all()
                    for _ in range(2):  # the second reads the order whole and keeps it (asked again)
                        # Pages of 7 by offset: each cut from the kept order (a page's rows are
                        # sorted again as they are read, so one page of all would hide a misplaced run).
                        listed = []
                        for offset in range(0, len(expected_ids) + 1, 7):
                            page, _, total = listed_page(reader, where, limit=7, cursor=None, sort=sort, offset=offset)
                            listed += [row["id"] for row in page]
                            assert total == len(expected_ids)
                        assert listed == expected_ids, (step, name, where, sort)
            reference.commit()
            after = list_cache(reader.connection())
            if before is None:  # PostgreSQL: nothing kept
                assert after is None
                continue
            if CHANGES[name] is None:
                assert after.stamp == before.stamp, name
            else:
                assert after.stamp.version != before.stamp.version, name
                assert (after.stamp.reshaped != before.stamp.reshaped) == CHANGES[name], name


def test_a_new_run_costs_a_count_of_the_runs_since_the_base(tmp_path, monkeypatch):
    """After a run is added, a total is its base's plus a count from the base's id on; past
    RECOUNT_AFTER runs since the base, one whole count again, which sets a new base."""
    monkeypatch.setattr(run_list_cache, "RECOUNT_AFTER", 3)
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    sessions, rng = session_factory(engine), random.Random(0)
    where = RunFilter(kind="sim")
    with sessions() as reader, sessions() as writer:
        for _ in range(10):
            add_run(writer, _record(rng))
        writer.commit()
        matching_count(reader, where)
        reader.commit()
        first = list_cache(reader.connection()).bases[(("kind", "sim"),)]
        assert first.newest == 10
        # runs added -> the base's newest id: kept while at most 3 runs came since, then 14 anew
        for added, base_newest in [(1, 10), (2, 10), (3, 10), (4, 14), (5, 14)]:
            add_run(writer, _record(rng))
            writer.commit()
            reader.commit()
            expected = writer.scalar(select(func.count()).where(Run.kind == "sim"))
            assert matching_count(reader, where) == expected
            base = list_cache(reader.connection()).bases[(("kind", "sim"),)]
            assert base.newest == base_newest, added
            assert base == first or added > 3
    engine.dispose()


def test_the_count_since_a_base_reads_the_ids_range_not_a_criterions_index(tmp_path):
    """SQLite would count a zeta0 range since a run through the zeta0 index (every run in the
    range) and a tag through every run of the tag; the count since reads only the newest runs."""
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    with engine.connect() as connection:
        for criteria in [("zeta0_min", "zeta0_max"), ("tag",), ("q", "kind")]:
            statement = _count_statement(criteria, since=True).compile(engine)
            values = {"zeta0_min": 0.8, "zeta0_max": 0.9, "tag": "a", "q": "xyz", "kind": "sim", "since": 7}
            parameters = statement.construct_params(values)
            positional = tuple(parameters[name] for name in statement.positiontup)
            plan = connection.exec_driver_sql(f"EXPLAIN QUERY PLAN {statement}", positional)
            steps = [row[3] for row in plan if row[3].startswith(("SEARCH", "SCAN"))]
            for step in steps:  # runs by a range of ids (or the ids of tags), tags from the base's id on
                if " runs " in f"{step} ":
                    assert "rowid>?" in step or "rowid=?" in step, steps
                elif "run_search" in step:  # the search index's look-up, with its rowid from the base's on
                    assert step.startswith("SCAN run_search VIRTUAL TABLE INDEX") and step.endswith(">"), steps
                else:
                    assert "run_tags" in step and "run_id>?" in step, steps
    engine.dispose()


def test_a_cache_keeps_the_most_recent_orders_within_its_bound(monkeypatch):
    monkeypatch.setattr(run_list_cache, "IDS_KEPT", 5)
    cache = ListCache(Stamp(1, 1, 10))
    cache.keep_order(("a", "-climb"), array("q", [1, 2, 3]), 10)
    cache.keep_order(("b", "-climb"), array("q", [4, 5]), 10)
    assert cache.order(("a", "-climb")) is not None  # used: now the most recent
    cache.keep_order(("c", "-climb"), array("q", [6]), 10)
    assert cache.order(("b", "-climb")) is None and list(cache.order(("a", "-climb"))) == [1, 2, 3]
    assert cache.ids_kept == 4 and set(cache.newest) == {("a", "-climb"), ("c", "-climb")}


def test_a_cache_forgets_its_counts_past_its_bound(monkeypatch):
    monkeypatch.setattr(run_list_cache, "COUNTS_KEPT", 2)
    cache = ListCache(Stamp(1, 1, 10))
    for key in ("a", "b", "c"):
        cache.keep_count((key,), 1)
    assert list(cache.counts) == [("c",)]


def test_a_renewed_cache_keeps_only_bases_and_orders_and_those_only_while_not_reshaped():
    cache = ListCache(Stamp(1, 1, 10))
    cache.keep_count(("a",), 4)
    cache.keep_base(("a",), run_list_cache.Base(3, 10))
    cache.keep_order((("a",), "-id"), array("q", [9, 1]), 10)
    cache.keep_order((("a",), "-climb"), array("q", [1, 9]), 10)
    appended = cache.renewed(Stamp(2, 1, 11))
    assert appended.counts == {} and appended.bases == cache.bases
    assert list(appended.orders) == [(("a",), "-id"), (("a",), "-climb")]
    assert appended.behind == {(("a",), "-id"), (("a",), "-climb")}, "each to be brought up to date when asked"
    reshaped = cache.renewed(Stamp(2, 2, 11))
    assert reshaped.bases == {} and not reshaped.orders and reshaped.ids_kept == 0
