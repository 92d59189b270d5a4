"""The run list's pages and exports, read and encoded in worker processes, not the service's own.

The service is one process: it owns the robot link, the job runner and the 3D view, and its
event loop answers the e-stop. Every page of ``GET /api/v1/runs`` it read itself cost it about
4 ms of its GIL (the SQL's Python side, the rows, validating and encoding the JSON), and under 20
clients that queue, not the cores, set the latency: p95 136 ms with a third of the machine idle
(``scripts/bench_load.py``, docs/service.md). So a page is read where no request of the service
waits for its GIL: in the ``reads`` pool (:mod:`backend.workers.pools`), whose workers each keep an
engine on the store and hand back the page's finished JSON, which the route forwards as it is. An
export goes the same way, a part of 1000 runs per call (``exports.export_part``), so it streams
without holding the service's GIL, and exports and pages take turns at the workers between parts.

What the workers run — listing the runs and planning, reading and joining an export's parts — is
the records and exports services' own functions, handed over as :class:`RunReads` (``create_app``
assembles it): the workers import no service.

A worker reads through its own connection, so it sees what was committed before the request
came (a run just stored is listed); the page is the same JSON the route would encode itself
(:data:`PAGE` is its response model). The page's ``total`` is counted once per filter while the
store is unchanged, and after a new run only from the runs since the last count
(``repositories.run_list_cache.matching_count``).
"""

from __future__ import annotations

import asyncio
from collections import OrderedDict, deque
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass
from typing import Any

from pydantic import TypeAdapter
from sqlalchemy.orm import Session, sessionmaker

from backend.schemas import RunPage
from backend.store.database import make_engine, session_factory
from backend.workers.pools import ComputePool

PAGE = TypeAdapter(RunPage)
STORES_KEPT = 4  # engines a worker keeps open (one in service; tests open one per temporary store)
_stores: OrderedDict[str, sessionmaker[Session]] = OrderedDict()  # in a worker: by database URL, newest last


@dataclass(frozen=True)
class RunReads:
    """The functions the reads run, the services' own (module-level: they travel to the workers by name).

    Attributes:
        list_runs: ``(session, where, *, limit, cursor, sort, offset) -> (rows, next_cursor, total)``,
            a page of runs and how many match (``backend.services.runs.list_runs``); run in a worker.
        plan_export: ``(session, where, format_) -> plan``; run in a worker.
        export_part: ``(session, where, plan, part) -> str``, one part's text; run in a worker.
        export_head, export_tail: ``(plan) -> str``, the text before and after the parts; run here.
        joined: ``(plan, text, follows) -> str``, a part's text as it goes out after the ones before.
    """

    list_runs: Callable[..., tuple[list, int | None, int]]
    plan_export: Callable[..., Any]
    export_part: Callable[..., str]
    export_head: Callable[[Any], str]
    export_tail: Callable[[Any], str]
    joined: Callable[[Any, str, bool], str]


def loaded(reads: RunReads) -> None:
    """A read worker's first task (``functools.partial(loaded, reads)``): nothing to run — receiving
    ``reads`` imported the modules its functions live in (the store, the schemas a first page needs)."""


class StoreReads:
    """Awaitable reads of the store at ``database_url``, each in a worker of ``pool``, running ``reads``."""

    def __init__(self, pool: ComputePool, database_url: str, reads: RunReads):
        self.pool = pool
        self.database_url = database_url
        self.reads = reads

    async def runs_page(self, where, *, limit: int, cursor: int | None, sort: str, offset: int) -> bytes:
        """A page of the runs ``where`` (a ``RunFilter``) selects as the API's ``RunPage`` JSON (see
        :func:`backend.services.runs.list_runs` for the sort, cursor and offset)."""
        return await self._read(runs_page_json, self.reads.list_runs, where, limit, cursor, sort, offset)

    async def export_plan(self, where, format_: str):
        """An export's plan (``exports.plan_export``): asked before its response starts, so a busy
        pool or a failing store is a status, not a cut-off download."""
        return await self._read(self.reads.plan_export, where, format_)

    async def export_text(self, where, plan) -> AsyncIterator[str]:
        """The export ``plan`` describes, as text: its head, a part per worker call, its tail
        (``exports.export``: the same parts read in this process). As many parts are read at
        once as the pool has workers, so the connection and the workers wait for each other
        least; they come out in order."""
        reads = self.reads
        yield reads.export_head(plan)
        parts = iter(range(len(plan.ends)))
        reading: deque[asyncio.Future] = deque()

        def read_next() -> None:
            part = next(parts, None)
            if part is not None:
                reading.append(asyncio.ensure_future(self._read(reads.export_part, where, plan, part)))

        for _ in range(self.pool.workers):
            read_next()
        follows = False
        try:
            while reading:
                text = await reading.popleft()
                read_next()
                yield reads.joined(plan, text, follows)
                follows = follows or bool(text)
        finally:
            for pending in reading:  # the client went away: no more parts (one under way finishes unread)
                pending.cancel()
        yield reads.export_tail(plan)

    async def _read(self, work, *args):
        """``work(session, *args)`` in a worker, with a session on the store."""
        return await self.pool.call(_in_session, work, self.database_url, *args)


def runs_page_json(
    session: Session, list_runs: Callable, where, limit: int, cursor: int | None, sort: str, offset: int
) -> bytes:
    """In a worker: the page ``list_runs`` reads, encoded (:meth:`StoreReads.runs_page`)."""
    rows, next_cursor, total = list_runs(session, where, limit=limit, cursor=cursor, sort=sort, offset=offset)
    return PAGE.dump_json(PAGE.validate_python({"items": rows, "next_cursor": next_cursor, "total": total}))


def _in_session(work, database_url: str, *args):
    """In a worker: ``work(session, *args)`` in a session on ``database_url``."""
    with _sessions(database_url)() as session:
        return work(session, *args)


def _sessions(database_url: str) -> sessionmaker[Session]:
    """This worker's sessions on ``database_url``, its engine made once and kept while in use."""
    if database_url in _stores:
        _stores.move_to_end(database_url)
        return _stores[database_url]
    _stores[database_url] = session_factory(make_engine(database_url))
    while len(_stores) > STORES_KEPT:
        _url, oldest = _stores.popitem(last=False)
        oldest.kw["bind"].dispose()
    return _stores[database_url]
