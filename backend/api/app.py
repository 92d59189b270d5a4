"""The FastAPI application: ``create_app(settings)`` assembles the service and nothing more.

It builds the store, the job runner and the robot service, keeps them on ``app.state``, and
mounts the routes (``backend/api/routes``: one module per resource, thin — route → service →
repository), the error table (``errors``), the middlewares every request passes first — security
headers, the Host and Origin allow-list, the token, the body limit (``security``) — and the
panel's static files. What a route needs it asks of ``deps``.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import threading
from pathlib import Path

import anyio.to_thread
from fastapi import FastAPI
from fastapi.staticfiles import StaticFiles

from backend.api import errors, security, statuses
from backend.api.deps import Database
from backend.api.identity import Identities
from backend.api.routes import calibrations, catalog, experiments, jobs, robot, runs, sim, site, view, worlds
from backend.api.token_file import api_token
from backend.services import exports, quick_calls, studies
from backend.services import runs as run_service
from backend.services.job_runner import JobRunner
from backend.services.robot import RobotService
from backend.services.storage_waits import Waiting, now_or_when_room
from backend.services.view import ViewContext, ViewFactory, ViewStarter
from backend.settings import Settings
from backend.store.database import ensure_reserve, make_engine, migrate, session_factory
from backend.store.people import PeopleFile
from backend.workers.pools import Compute
from backend.workers.store_reads import RunReads, StoreReads, loaded

log = logging.getLogger("parkourlab.api")
# The control panel's static files (frontend/panel): located, not imported — the frontend sits above
# the backend in the layers, and the backend only serves its files.
PANEL_DIR = Path(__file__).resolve().parents[2] / "frontend" / "panel"
ROUTERS = (site, catalog, experiments, runs, calibrations, worlds, jobs, robot, view, sim)
# Threads that run the sync routes (database work; compute is awaited in worker processes, the
# e-stop is async). anyio's default is 40: under load 40 threads ping-pong the GIL once per row
# SQLite steps, and on this 2-core machine 20 clients got 116 pages/s, p95 378 ms; with 4, 143
# pages/s, p95 199 ms (scripts/bench_load.py). Nothing a sync route does waits long: a request
# that would (a simulation, a job's compute) awaits a worker instead.
REQUEST_THREADS = 4
LATCH_FILE = "estop-latch.json"  # in the data directory: a held e-stop survives a restart
# What the read workers run: the run and export services' functions (the workers import no service).
RUN_READS = RunReads(
    list_runs=run_service.list_runs,
    plan_export=exports.plan_export,
    export_part=exports.export_part,
    export_head=exports.export_head,
    export_tail=exports.export_tail,
    joined=exports.joined,
)


def create_app(
    settings: Settings,
    *,
    run_jobs: bool = True,
    view_factory: ViewFactory | None = None,
    warm_kernels: bool = False,
    compute: Compute | None = None,
) -> FastAPI:
    """The service. ``run_jobs=False`` leaves queued jobs alone (for tools that only read);
    ``warm_kernels`` starts the compute workers and loads the kernels in them once the service
    is up, so the first simulation does not wait for them (``parkour serve`` asks for it);
    ``compute`` lends the service worker pools that outlive it (tests share one set; by default
    it makes its own and stops them at shutdown);
    ``view_factory`` builds the 3D view at start-up, in the background (``cli.serve`` passes the
    viser one); ``app.state.view_starter`` holds it once built."""
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    engine = make_engine(settings.database_url)
    sessions = session_factory(engine)
    token, _ = api_token(settings.data_dir)
    owns_compute = compute is None
    compute = compute or Compute(warm_up=quick_calls.warm_up, jobs_warm_up=studies.warm_job_kinds,
                                 reads_warm_up=functools.partial(loaded, RUN_READS))  # fmt: skip
    waiting = Waiting()  # writes that wait for disk space: the health check lists them
    stopping = threading.Event()
    runner = JobRunner(sessions, compute.jobs, dask_address=settings.dask_address, waiting=waiting)
    robot_service = RobotService(sessions, latch_path=settings.data_dir / LATCH_FILE)

    @contextlib.asynccontextmanager
    async def lifespan(app: FastAPI):
        anyio.to_thread.current_default_thread_limiter().total_tokens = REQUEST_THREADS
        migrate(engine)
        ensure_reserve(engine)  # the room deletes need on a full disk (store/database.py)
        # Live runs the previous process died during: stored as interrupted, nothing re-armed. On a
        # full disk that waits for space on a thread of its own: reads and DELETE must come up.
        now_or_when_room(
            robot_service.recover, what="storing the live runs the last stop cut short", engine=engine,
            stopping=stopping, waiting=waiting,
        )  # fmt: skip
        if warm_kernels:
            compute.warm()
        if run_jobs:
            runner.start()
        if view_factory is not None:
            context = ViewContext(sessions=sessions, robot_service=robot_service)
            app.state.view_starter = ViewStarter(view_factory, context).start()
        yield
        stopping.set()
        if app.state.view_starter is not None:
            await asyncio.to_thread(app.state.view_starter.close)  # may wait for a view still starting
        robot_service.close()
        runner.stop()
        if owns_compute:
            compute.close()
        engine.dispose()

    app = FastAPI(
        title="ParkourLab",
        version="0.1.0",
        summary="Simulate, run, record and review the ParkourBot wall-climbing robot.",
        lifespan=lifespan,
        docs_url=None,  # served by routes/site.py from local assets: the lab has no internet at run time
        redoc_url=None,
    )
    # Static assets go compressed to a browser that takes gzip (Plotly, the largest, from a copy
    # compressed once: routes/site.py); the API's responses and its event streams do not pass here.
    app.mount("/static/swagger", site.compressed(StaticFiles(directory=site.SWAGGER_ASSETS)), name="swagger")
    app.mount("/panel", site.compressed(StaticFiles(directory=PANEL_DIR, html=True)), name="panel")
    app.state.settings = settings
    app.state.sessions = sessions
    app.state.database = Database(sessions)
    app.state.token = token
    app.state.identities = Identities(token, PeopleFile(settings.data_dir))
    app.state.runner = runner if run_jobs else None
    app.state.robot = robot_service
    app.state.compute = compute
    app.state.reads = StoreReads(compute.reads, settings.database_url, RUN_READS)
    app.state.view_starter = None
    app.state.waiting = waiting
    security.install(app, settings)  # headers, Host/Origin allow-list, token first, body limit
    errors.install(app)
    for module in ROUTERS:
        app.include_router(module.router)
    statuses.install(app)  # the statuses each operation answers, in the OpenAPI document
    return app
