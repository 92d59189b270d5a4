"""The run list's pages read in worker processes (backend/workers/store_reads.py): the same page
the records service lists, as the API's JSON, seeing what was just stored (its total too); a worker
keeps few engines."""

import asyncio
import functools
import json

from backend.api.app import RUN_READS
from backend.repositories import runs as store_runs
from backend.repositories.runs import RunFilter
from backend.schemas import RunPage
from backend.services import exports
from backend.services import runs as records
from backend.store.database import make_engine, migrate, sqlite_url
from backend.workers import store_reads
from backend.workers.pools import ComputePool


def test_a_page_read_in_a_worker_is_the_records_page_as_the_api_encodes_it(tmp_path, sessions, make_run):
    for zeta0 in (0.86, 0.88, 0.9):
        make_run(zeta0=zeta0, tags=["b", "a"])
    url = sqlite_url(tmp_path)
    pool = ComputePool("reads-test", max_pending=4, niceness=0)
    try:
        reads = store_reads.StoreReads(pool, url, RUN_READS)
        where = RunFilter(zeta0_min=0.87)
        page = asyncio.run(reads.runs_page(where, limit=1, cursor=None, sort="-id", offset=0))
        with sessions() as session:
            rows, next_cursor, total = records.list_runs(session, where, limit=1, cursor=None)
            expected = RunPage.model_validate({"items": rows, "next_cursor": next_cursor, "total": total})
            expected = expected.model_dump(mode="json")
        assert json.loads(page) == expected and expected["next_cursor"] is not None and expected["total"] == 2
        assert expected["items"][0]["tags"] == ["a", "b"]
        make_run(zeta0=0.95)  # stored after the worker opened its connection: the next page sees it
        newest = json.loads(asyncio.run(reads.runs_page(where, limit=1, cursor=None, sort="-id", offset=0)))
        assert newest["items"][0]["controls"][0][1] == 0.95
        assert newest["total"] == 3, "the total counted before is not kept past a change"
    finally:
        pool.close()


def test_a_worker_keeps_a_few_stores_open_and_lets_the_oldest_go(tmp_path, monkeypatch):
    monkeypatch.setattr(store_reads, "_stores", type(store_reads._stores)())
    urls = []
    for k in range(store_reads.STORES_KEPT + 2):
        (tmp_path / f"store{k}").mkdir()
        engine = make_engine(sqlite_url(tmp_path / f"store{k}"))
        migrate(engine)
        engine.dispose()
        urls.append(sqlite_url(tmp_path / f"store{k}"))
        page = json.loads(
            store_reads._in_session(
                store_reads.runs_page_json, urls[-1], records.list_runs, RunFilter(), 10, None, "-id", 0
            )
        )
        assert page == {"items": [], "next_cursor": None, "total": 0}
    assert list(store_reads._stores) == urls[-store_reads.STORES_KEPT :]
    store_reads._in_session(
        store_reads.runs_page_json, urls[-store_reads.STORES_KEPT], records.list_runs, RunFilter(), 10, None, "-id", 0
    )
    assert list(store_reads._stores)[-1] == urls[-store_reads.STORES_KEPT], "the store just read is kept longest"


def test_an_export_read_in_workers_is_the_export_read_here(tmp_path, sessions, make_run, monkeypatch):
    """Parts read two at a time in the workers come out in order: the same text, chunk for chunk."""
    monkeypatch.setattr(store_runs, "EXPORT_BATCH", 2)  # here, where the plan is made: nine parts
    for k in range(17):
        make_run(zeta0=0.86 + 0.005 * k, tags=[f"t{k % 3}"])
    pool = ComputePool("reads-test", 2, max_pending=8, niceness=0)
    try:
        reads = store_reads.StoreReads(pool, sqlite_url(tmp_path), RUN_READS)
        for format_ in ("json", "csv"):
            with sessions() as session:
                plan = exports.plan_export(session, RunFilter(), format_)
            assert len(plan.ends) == 9

            async def read_all(plan=plan):
                return [chunk async for chunk in reads.export_text(RunFilter(), plan)]

            assert asyncio.run(read_all()) == list(exports.export(sessions, RunFilter(), format_))
    finally:
        pool.close()


# Run in a worker as eval(LOADED): a builtin, so the worker imports no test module (which would load the services).
LOADED = "sorted(m for m in ('backend.services.exports', 'backend.services.runs') if m in __import__('sys').modules)"


def test_a_read_worker_warms_up_by_receiving_the_read_functions():
    """Its first task loads the modules the reads run from (the records and exports services)."""
    warmed = ComputePool("reads-test", warm_up=functools.partial(store_reads.loaded, RUN_READS), niceness=0)
    plain = ComputePool("reads-plain", niceness=0)
    try:
        warmed.warm()
        assert warmed.run(eval, LOADED, timeout=60.0) == ["backend.services.exports", "backend.services.runs"]
        plain.warm()
        assert plain.run(eval, LOADED, timeout=60.0) == [], "a worker without the warm-up has not loaded them"
    finally:
        warmed.close()
        plain.close()
