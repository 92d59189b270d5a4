"""What routes ask FastAPI for: a database session, the token check, the service's parts, and the
shared path and query parameters (ids, pages, the run filters).

Every dependency here that does no blocking work is ``async``: FastAPI runs a plain ``def`` one in
a request thread, and each such hop costs about 0.8 ms of the service's CPU on this machine
(``scripts/bench_load.py``), more than most of them compute — and the e-stop's must never wait
for a request thread that compute or a busy store holds."""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, TypeVar

from fastapi import Depends, Header, HTTPException, Query, Request, status
from fastapi import Path as FastAPIPath
from fastapi.concurrency import run_in_threadpool
from fastapi.exceptions import RequestValidationError
from pydantic import Field
from sqlalchemy.orm import Session, sessionmaker

from backend import schemas
from backend.api.identity import who_label
from backend.api.security import require_token
from backend.repositories.run_filters import MIN_SEARCH
from backend.repositories.runs import RunFilter
from backend.services.job_runner import JobRunner
from backend.services.robot import RobotService
from backend.store.database import StorageFull, after_storage_full
from backend.workers.pools import ComputePool
from backend.workers.store_reads import StoreReads
from sim_core.control.registry import NAMES

T = TypeVar("T")
MAX_FILTER_IDS = 1000  # runs named at once in a filter (History's basket holds 50)
VIEW_NOT_STARTED = "the 3D view is not running (it starts with `parkour serve`)"


class Database:
    """The routes' way to the store: ``await db(work, *args)`` runs ``work(session, *args)`` in a
    request thread with a session of its own, opened and closed there, and returns what it
    returns — the route's whole database work in one thread hop, its answer serialised on the
    event loop.

    So a connection is held only while a request thread works. The sync ``Db`` dependency this
    replaces kept its session open from the route until FastAPI had serialised the answer, which
    for a sync route waits for a request thread too: under 50 clients, 15 requests held the pool's
    every connection while the 4 threads waited for one, and every request hung for 30 s and
    failed 500 (``scripts/bench_load.py --clients 50``, reproduced on the code before)."""

    def __init__(self, sessions: sessionmaker[Session]):
        self.sessions = sessions

    async def __call__(self, work: Callable[..., T], /, *args, **kwargs) -> T:
        return await run_in_threadpool(self.run, work, *args, **kwargs)

    def run(self, work: Callable[..., T], /, *args, **kwargs) -> T:
        """``work(session, *args, **kwargs)`` here, in this thread, with a session of its own. On a
        full disk — answered 507 (errors.py) — the WAL is folded so that a retry can fit."""
        with self.sessions() as session:
            try:
                return work(session, *args, **kwargs)
            except StorageFull:
                session.rollback()
                after_storage_full(session.get_bind())
                raise


async def database(request: Request) -> Database:
    return request.app.state.database


async def run_filter(
    experiment_id: Annotated[int | None, Query(ge=1, le=schemas.MAX_ID)] = None,
    world_id: Annotated[int | None, Query(ge=1, le=schemas.MAX_ID, description="runs in this stored world")] = None,
    kind: schemas.RunKind | None = None,
    status_: Annotated[schemas.RunStatus | None, Query(alias="status")] = None,
    tag: Annotated[str | None, Query(max_length=64)] = None,
    failure_code: Annotated[str | None, Query(max_length=32)] = None,
    end_reason: Annotated[
        str | None,
        Query(min_length=1, max_length=200, description='as recorded, or its kind: "error" matches "error: …"'),
    ] = None,
    loop: schemas.RunLoop | None = None,
    controller: Annotated[
        str | None, Query(min_length=1, max_length=16, description=f"a closed loop's law: {', '.join(NAMES)}")
    ] = None,
    q: Annotated[
        str | None,
        Query(
            min_length=1,
            max_length=200,
            description=f"text in the notes or a tag (any case), at least {MIN_SEARCH} characters; blank: no search",
        ),
    ] = None,
    ids: Annotated[
        list[Annotated[int, Field(ge=1, le=schemas.MAX_ID)]] | None,
        Query(max_length=MAX_FILTER_IDS, description="only these runs (a basket): ids=3&ids=7"),
    ] = None,
    zeta0_min: Annotated[float | None, Query(ge=0.0, le=1.0, allow_inf_nan=False)] = None,
    zeta0_max: Annotated[float | None, Query(ge=0.0, le=1.0, allow_inf_nan=False)] = None,
    psi0_min: Annotated[float | None, Query(ge=0.0, le=90.0, allow_inf_nan=False)] = None,
    psi0_max: Annotated[float | None, Query(ge=0.0, le=90.0, allow_inf_nan=False)] = None,
    created_after: Annotated[schemas.IsoDateTime | None, Query(description="ISO 8601, e.g. 2026-12-03")] = None,
    created_before: Annotated[schemas.IsoDateTime | None, Query(description="ISO 8601, e.g. 2026-12-03")] = None,
) -> RunFilter:
    """The run filters shared by list, export and aggregate."""
    q = q.strip() or None if q is not None else None
    if q is not None and len(q) < MIN_SEARCH:  # what an index of trigrams can find
        message = f"String should have at least {MIN_SEARCH} characters (a search reads an index of 3-letter pieces)"
        raise RequestValidationError([{"loc": ("query", "q"), "msg": message, "type": "string_too_short", "input": q}])
    return RunFilter(
        experiment_id=experiment_id,
        world_id=world_id,
        kind=kind,
        status=status_,
        tag=tag,
        failure_code=failure_code,
        end_reason=end_reason,
        loop=loop,
        controller=controller,
        zeta0_min=zeta0_min,
        zeta0_max=zeta0_max,
        psi0_min=psi0_min,
        psi0_max=psi0_max,
        created_after=created_after,
        created_before=created_before,
        q=q,
        ids=tuple(sorted(set(ids))) if ids else None,
    )


async def submitted_via(
    client: Annotated[
        str | None,
        Header(alias="X-Parkour-Client", pattern=schemas.CLIENT_PATTERN,
               description="the tool that submits (e.g. panel, a script's name): a label kept with the job"),
    ] = None,
) -> str | None:  # fmt: skip
    """The tool a request says it comes from: the ``X-Parkour-Client`` header (a label only: who
    submits is the token's person)."""
    return client


async def who(request: Request) -> str:
    """Who makes the request, as records keep it: the token's person, else (a route open to
    anyone, such as the e-stop) ``someone at <address>``. Async: a sync dependency would wait for a
    request thread, and the e-stop must not wait for a pool that compute has filled."""
    return who_label(request)


async def robot_service(request: Request) -> RobotService:
    return request.app.state.robot


async def quick_compute(request: Request) -> ComputePool:
    """The worker pool for API calls that compute."""
    return request.app.state.compute.quick


async def store_reads(request: Request) -> StoreReads:
    """The reads answered in worker processes (the run list's pages, exports)."""
    return request.app.state.reads


async def job_runner(request: Request) -> JobRunner | None:
    """The service's job runner, or None when it runs no jobs (``create_app(run_jobs=False)``)."""
    return request.app.state.runner


def view_unavailable_reason(request: Request) -> str:
    starter = request.app.state.view_starter
    return VIEW_NOT_STARTED if starter is None else starter.unavailable_reason


def view_of(request: Request):
    """The 3D view, or a 503 saying why there is none (not started, still starting, failed)."""
    starter = request.app.state.view_starter
    view = None if starter is None else starter.view
    if view is None:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, view_unavailable_reason(request))
    return view


async def scene_view(request: Request):
    """The ``SceneView`` dependency: :func:`view_of` the request."""
    return view_of(request)


Db = Annotated[Database, Depends(database)]
RunQuery = Annotated[RunFilter, Depends(run_filter)]
Robot = Annotated[RobotService, Depends(robot_service)]
Runner = Annotated[JobRunner | None, Depends(job_runner)]
QuickCompute = Annotated[ComputePool, Depends(quick_compute)]
Reads = Annotated[StoreReads, Depends(store_reads)]
SubmittedVia = Annotated[str | None, Depends(submitted_via)]
Who = Annotated[str, Depends(who)]
SceneView = Annotated[object, Depends(scene_view)]  # frontend.viewer's view (the backend does not import it)
AUTHORIZED = [Depends(require_token)]  # every mutating route's dependencies
PageLimit = Annotated[int, Query(ge=1, le=schemas.MAX_PAGE, description="items per page")]
Cursor = Annotated[int | None, Query(ge=1, le=schemas.MAX_ID, description="next_cursor of the previous page")]
RecordId = Annotated[int, FastAPIPath(ge=1, le=schemas.MAX_ID)]
OptionalRecordId = Annotated[int | None, Query(ge=1, le=schemas.MAX_ID)]
PresetQuery = Annotated[
    str | None, Query(min_length=1, max_length=64, pattern=schemas.PRESET_PATTERN, description="a stored calibration")
]
