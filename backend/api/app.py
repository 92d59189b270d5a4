"""The FastAPI application: ``create_app(settings)``.

Routes are thin: they check the token where state changes, open a session, call
``backend.services`` and shape the answer. Errors a client can fix come back as 4xx with the
field and the allowed range; nothing returns a traceback.
"""

from __future__ import annotations

import asyncio
import contextlib
import datetime
import json
import logging
import secrets
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated

import fastapi_offline
import plotly
from fastapi import Depends, FastAPI, HTTPException, Query, Request, WebSocket, WebSocketDisconnect, status
from fastapi import Path as FastAPIPath
from fastapi.encoders import jsonable_encoder
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, RedirectResponse, StreamingResponse
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from fastapi.staticfiles import StaticFiles
from pydantic import Field
from sqlalchemy import select
from sqlalchemy.orm import Session

from backend import schemas
from backend.robot.link import LinkError
from backend.services import jobs, records, simulation
from backend.services.robot import RobotService, RobotUnavailable
from backend.services.robot_records import replay_run
from backend.services.view import ViewContext, ViewFactory, ViewStarter
from backend.settings import Settings
from backend.store.database import make_engine, migrate, session_factory
from sim_core import FixedPointNotFound, ParameterError

log = logging.getLogger("parkourlab.api")
TOKEN_FILE = "api_token"
EVENT_POLL_S = 0.25  # progress comes from committed chunks; a quarter second is live enough
SWAGGER_ASSETS = Path(fastapi_offline.__file__).parent / "static"  # Swagger UI 5: reads OpenAPI 3.1
PLOTLY_JS = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"  # served locally: no CDN
# The control panel's static files (frontend/panel): located, not imported — the frontend sits above
# the backend in the layers, and the backend only serves its files.
PANEL_DIR = Path(__file__).resolve().parents[2] / "frontend" / "panel"
PageLimit = Annotated[int, Query(ge=1, le=records.MAX_PAGE, description="items per page")]
bearer = HTTPBearer(auto_error=False)


def get_session(request: Request) -> Iterator[Session]:
    with request.app.state.sessions() as session:
        yield session


def require_token(
    request: Request, credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer)]
) -> None:
    """Mutating calls carry ``Authorization: Bearer <token>``; the token is in the data directory."""
    if credentials is None or not secrets.compare_digest(credentials.credentials, request.app.state.token):
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED,
            "a valid bearer token is required for changes (see api_token in the data directory)",
            headers={"WWW-Authenticate": "Bearer"},
        )


def run_filter(
    experiment_id: Annotated[int | None, Query(ge=1, le=schemas.MAX_ID)] = None,
    kind: Annotated[str | None, Query(pattern="^(sim|robot|replay)$")] = None,
    status_: Annotated[str | None, Query(alias="status", pattern="^(done|failed)$")] = None,
    tag: Annotated[str | None, Query(max_length=64)] = None,
    failure_code: Annotated[str | None, Query(max_length=32)] = None,
    zeta0_min: Annotated[float | None, Query(ge=0.0, le=1.0)] = None,
    zeta0_max: Annotated[float | None, Query(ge=0.0, le=1.0)] = None,
    psi0_min: Annotated[float | None, Query(ge=0.0, le=90.0)] = None,
    psi0_max: Annotated[float | None, Query(ge=0.0, le=90.0)] = None,
    created_after: datetime.datetime | None = None,
    created_before: datetime.datetime | None = None,
) -> records.RunFilter:
    """The run filters shared by list, export and aggregate."""
    return records.RunFilter(
        experiment_id=experiment_id,
        kind=kind,
        status=status_,
        tag=tag,
        failure_code=failure_code,
        zeta0_min=zeta0_min,
        zeta0_max=zeta0_max,
        psi0_min=psi0_min,
        psi0_max=psi0_max,
        created_after=created_after,
        created_before=created_before,
    )


Db = Annotated[Session, Depends(get_session)]
RunQuery = Annotated[records.RunFilter, Depends(run_filter)]
AUTHORIZED = [Depends(require_token)]
Cursor = Annotated[int | None, Query(ge=1, le=schemas.MAX_ID, description="next_cursor of the previous page")]
RecordId = Annotated[int, FastAPIPath(ge=1, le=schemas.MAX_ID)]


def api_token(data_dir: Path) -> tuple[str, bool]:
    """The bearer token for mutating calls: ``(token, created_now)``; created once, kept in the data dir."""
    path = Path(data_dir) / TOKEN_FILE
    if path.exists():
        return path.read_text().strip(), False
    path.parent.mkdir(parents=True, exist_ok=True)
    token = secrets.token_urlsafe(32)
    path.touch(mode=0o600)
    path.write_text(token + "\n")
    return token, True


def create_app(
    settings: Settings,
    *,
    run_jobs: bool = True,
    view_factory: ViewFactory | None = None,
    warm_kernels: bool = False,
) -> FastAPI:
    """The service. ``run_jobs=False`` leaves queued jobs alone (for tools that only read);
    ``warm_kernels`` loads the simulation kernels in the background once the service is up, so
    the first simulation does not wait for them (``parkour serve`` asks for it);
    ``view_factory`` builds the 3D view at start-up, in the background (``cli.serve`` passes the
    viser one); ``app.state.view_starter`` holds it once built."""
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    engine = make_engine(settings.database_url)
    sessions = session_factory(engine)
    token, _ = api_token(settings.data_dir)
    runner = jobs.JobRunner(sessions, dask_address=settings.dask_address)
    robot = RobotService(sessions)

    @contextlib.asynccontextmanager
    async def lifespan(app: FastAPI):
        migrate(engine)
        robot.recover()  # live runs the previous process died during: stored as interrupted, nothing re-armed
        if warm_kernels:
            threading.Thread(target=simulation.warm_up, name="warm-kernels", daemon=True).start()
        if run_jobs:
            runner.start()
        if view_factory is not None:
            context = ViewContext(sessions=sessions, robot_service=robot)
            app.state.view_starter = ViewStarter(view_factory, context).start()
        yield
        if app.state.view_starter is not None:
            await asyncio.to_thread(app.state.view_starter.close)  # may wait for a view still starting
        robot.close()
        runner.stop()
        engine.dispose()

    app = FastAPI(
        title="ParkourLab",
        version="0.1.0",
        summary="Simulate, run, record and review the ParkourBot wall-climbing robot.",
        lifespan=lifespan,
        docs_url=None,  # served below from local assets: the lab has no internet at run time
        redoc_url=None,
    )
    app.mount("/static/swagger", StaticFiles(directory=SWAGGER_ASSETS), name="swagger")
    app.mount("/panel", StaticFiles(directory=PANEL_DIR, html=True), name="panel")
    app.state.settings = settings
    app.state.sessions = sessions
    app.state.token = token
    app.state.view_starter = None

    @app.middleware("http")
    async def limit_request_size(request: Request, call_next):
        length = request.headers.get("content-length")
        if length is not None and (not length.isdigit() or int(length) > settings.max_request_bytes):
            return JSONResponse(
                {"detail": f"request body must be at most {settings.max_request_bytes} bytes"},
                status_code=status.HTTP_413_CONTENT_TOO_LARGE,
            )
        return await call_next(request)

    @app.exception_handler(records.NotFound)
    async def not_found(_request, error):
        return JSONResponse({"detail": str(error)}, status_code=status.HTTP_404_NOT_FOUND)

    @app.exception_handler(records.Conflict)
    async def conflict(_request, error):
        return JSONResponse({"detail": str(error)}, status_code=status.HTTP_409_CONFLICT)

    @app.exception_handler(ParameterError)
    async def bad_parameter(_request, error: ParameterError):
        body = {"detail": [{"loc": ["body", error.field], "msg": str(error), "type": "value_error"}]}
        return JSONResponse(body, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)

    @app.exception_handler(RobotUnavailable)
    async def robot_unavailable(_request, error):
        return JSONResponse({"detail": str(error)}, status_code=status.HTTP_409_CONFLICT)

    @app.exception_handler(LinkError)
    async def link_error(_request, error):
        return JSONResponse({"detail": f"robot link: {error}"}, status_code=status.HTTP_503_SERVICE_UNAVAILABLE)

    @app.exception_handler(FixedPointNotFound)
    async def no_fixed_point(_request, error):
        return JSONResponse({"detail": str(error)}, status_code=status.HTTP_422_UNPROCESSABLE_CONTENT)

    @app.get("/", include_in_schema=False)
    def index() -> RedirectResponse:
        return RedirectResponse("/panel/")

    @app.get("/static/plotly.min.js", include_in_schema=False)
    def plotly_js() -> FileResponse:
        return FileResponse(PLOTLY_JS, media_type="text/javascript")

    @app.get("/docs", include_in_schema=False)
    def docs() -> HTMLResponse:
        return get_swagger_ui_html(
            openapi_url=app.openapi_url,
            title="ParkourLab API",
            swagger_js_url="/static/swagger/swagger-ui-bundle.js",
            swagger_css_url="/static/swagger/swagger-ui.css",
            swagger_favicon_url="/static/swagger/favicon.png",
        )

    @app.get("/api/v1/health", tags=["service"])
    def health(db: Db) -> dict:
        db.execute(select(1))
        return {"status": "ok", "database": engine.dialect.name, "code_version": simulation.current_code_version()}

    # Experiments
    @app.post(
        "/api/v1/experiments",
        status_code=201,
        dependencies=AUTHORIZED,
        response_model=schemas.ExperimentOut,
        tags=["experiments"],
    )
    def create_experiment(body: schemas.ExperimentCreate, db: Db):
        return _experiment_out(db, records.create_experiment(db, body))

    @app.get("/api/v1/experiments", response_model=schemas.Page, tags=["experiments"])
    def list_experiments(db: Db, limit: PageLimit = 50, cursor: Cursor = None):
        rows, next_cursor = records.list_experiments(db, limit=limit, cursor=cursor)
        return {"items": [_experiment_out(db, row) for row in rows], "next_cursor": next_cursor}

    @app.get("/api/v1/experiments/{experiment_id}", response_model=schemas.ExperimentOut, tags=["experiments"])
    def get_experiment(experiment_id: RecordId, db: Db):
        return _experiment_out(db, records.get_experiment(db, experiment_id))

    @app.patch(
        "/api/v1/experiments/{experiment_id}",
        dependencies=AUTHORIZED,
        response_model=schemas.ExperimentOut,
        tags=["experiments"],
    )
    def update_experiment(experiment_id: RecordId, body: schemas.ExperimentUpdate, db: Db):
        return _experiment_out(db, records.update_experiment(db, experiment_id, body))

    @app.delete("/api/v1/experiments/{experiment_id}", status_code=204, dependencies=AUTHORIZED, tags=["experiments"])
    def delete_experiment(experiment_id: RecordId, db: Db) -> None:
        records.delete_experiment(db, experiment_id)

    # Runs
    @app.post("/api/v1/runs", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail, tags=["runs"])
    def create_run(body: schemas.RunCreate, db: Db):
        return _run_out(records.create_run(db, body), detail=True)

    @app.get("/api/v1/runs", response_model=schemas.Page, tags=["runs"])
    def list_runs(
        db: Db,
        where: RunQuery,
        limit: PageLimit = 50,
        cursor: Cursor = None,
        sort: Annotated[str, Query(pattern=f"^({'|'.join(records.SORTS)})$", description="-climb: best first")] = "-id",
        offset: Annotated[int, Query(ge=0, le=10_000_000, description="for sorts other than id")] = 0,
    ):
        """Runs matching the filters. Sorted by id, ``next_cursor`` pages by keyset; sorted by another
        field, pass ``next_cursor`` back as ``offset``."""
        rows, next_cursor = records.list_runs(db, where, limit=limit, cursor=cursor, sort=sort, offset=offset)
        return {"items": [_run_out(row) for row in rows], "next_cursor": next_cursor}

    @app.get("/api/v1/runs/export", tags=["runs"], response_class=StreamingResponse)
    def export_runs(
        db: Db, where: RunQuery, format_: Annotated[str, Query(alias="format", pattern="^(csv|json)$")] = "csv"
    ):
        """Every run matching the filters, streamed, with tags, timings and parameters (not the path)."""
        rows = records.export_rows(sessions, where)
        media = "text/csv" if format_ == "csv" else "application/json"
        body = records.rows_as_csv(rows) if format_ == "csv" else records.rows_as_json(rows)
        disposition = {"Content-Disposition": f'attachment; filename="runs.{format_}"'}
        return StreamingResponse(body, media_type=media, headers=disposition)

    @app.get("/api/v1/runs/compare", tags=["runs"])
    def compare_runs(
        db: Db,
        ids: Annotated[
            list[Annotated[int, Field(ge=1, le=schemas.MAX_ID)]],
            Query(min_length=2, max_length=records.MAX_COMPARE, description="run ids"),
        ],
        only_differences: bool = True,
    ) -> dict:
        """Runs side by side as flat fields; by default only the fields whose values differ."""
        return records.compare_runs(db, ids, only_differences=only_differences)

    @app.get("/api/v1/runs/aggregate", tags=["runs"])
    def aggregate_runs(
        db: Db,
        where: RunQuery,
        by: Annotated[str, Query(pattern=f"^({'|'.join(records.GROUP_BY)})$")] = "zeta0",
    ) -> dict:
        """Runs grouped by a parameter or tag: count, mean, std, min and max of climb and jumps completed."""
        return {"by": by, "groups": records.aggregate_runs(db, where, by)}

    @app.get("/api/v1/runs/{run_id}", response_model=schemas.RunDetail, tags=["runs"])
    def get_run(run_id: RecordId, db: Db):
        return _run_out(records.get_run(db, run_id), detail=True)

    @app.get("/api/v1/runs/{run_id}/trajectory", tags=["runs"])
    def get_trajectory(run_id: RecordId, db: Db) -> dict:
        run = records.get_run(db, run_id)
        if run.trajectory is None:
            raise records.NotFound("trajectory of run", run_id)
        columns = simulation.unpack_trajectory(run.trajectory)
        return {"units": "nondimensional", "columns": {name: values.tolist() for name, values in columns.items()}}

    @app.post(
        "/api/v1/runs/{run_id}/replay",
        status_code=201,
        dependencies=AUTHORIZED,
        response_model=schemas.RunDetail,
        tags=["runs"],
    )
    def replay(run_id: RecordId, db: Db):
        """Analyse a robot run's recorded tracker frames again, stored as a run of kind replay."""
        return _run_out(replay_run(db, run_id), detail=True)

    @app.patch("/api/v1/runs/{run_id}", dependencies=AUTHORIZED, response_model=schemas.RunOut, tags=["runs"])
    def update_run(run_id: RecordId, body: schemas.RunUpdate, db: Db):
        return _run_out(records.update_run(db, run_id, tags=body.tags, notes=body.notes))

    @app.delete("/api/v1/runs/{run_id}", status_code=204, dependencies=AUTHORIZED, tags=["runs"])
    def delete_run(run_id: RecordId, db: Db) -> None:
        records.delete_run(db, run_id)

    # Jobs
    @app.post("/api/v1/jobs", status_code=202, dependencies=AUTHORIZED, response_model=schemas.JobOut, tags=["jobs"])
    def create_job(body: schemas.JobCreate, db: Db):
        job = jobs.create_job(db, body)
        if run_jobs:
            runner.submit(job.id)
        return _job_out(job)

    @app.get("/api/v1/jobs", response_model=schemas.Page, tags=["jobs"])
    def list_jobs(
        db: Db,
        limit: PageLimit = 50,
        cursor: Cursor = None,
        state: Annotated[str | None, Query(pattern="^(queued|running|cancelling|cancelled|done|failed)$")] = None,
    ):
        rows, next_cursor = jobs.list_jobs(db, state=state, limit=limit, cursor=cursor)
        return {"items": [_job_out(row) for row in rows], "next_cursor": next_cursor}

    @app.get("/api/v1/jobs/{job_id}", response_model=schemas.JobOut, tags=["jobs"])
    def get_job(job_id: RecordId, db: Db):
        return _job_out(jobs.get_job(db, job_id))

    @app.get("/api/v1/jobs/{job_id}/results", response_model=schemas.JobResults, tags=["jobs"])
    def job_results(job_id: RecordId, db: Db):
        job = jobs.get_job(db, job_id)
        if job.kind != "mjtf":
            return {"job": _job_out(job), "result": job.result}
        return {"job": _job_out(job), "levels": [_finite(level) for level in jobs.level_summaries(db, job)]}

    @app.get("/api/v1/jobs/{job_id}/events", tags=["jobs"], response_class=StreamingResponse)
    async def job_events(
        job_id: RecordId,
        request: Request,
        timeout: Annotated[
            float, Query(gt=0, le=86_400, description="close the stream after this many seconds")
        ] = 3600,
    ):
        """Server-sent events: a ``progress`` event whenever the job's state or count changes; the
        stream ends after the job's final state (done, cancelled, failed) or ``timeout``."""

        def snapshot() -> dict:
            with sessions() as db:
                return _job_out(jobs.get_job(db, job_id))

        first = await asyncio.to_thread(snapshot)  # a missing job is a 404 before the stream opens

        async def stream():
            job, last, deadline = first, None, time.monotonic() + timeout
            while True:
                key = (job["state"], job["completed"])
                if key != last:
                    last = key
                    yield f"event: progress\ndata: {json.dumps(jsonable_encoder(job))}\n\n"
                if job["state"] in jobs.FINAL or time.monotonic() > deadline or await request.is_disconnected():
                    return
                await asyncio.sleep(EVENT_POLL_S)
                job = await asyncio.to_thread(snapshot)

        return StreamingResponse(stream(), media_type="text/event-stream", headers={"Cache-Control": "no-cache"})

    @app.post("/api/v1/jobs/{job_id}/cancel", dependencies=AUTHORIZED, response_model=schemas.JobOut, tags=["jobs"])
    def cancel_job(job_id: RecordId, db: Db):
        return _job_out(jobs.cancel_job(db, job_id))

    # The robot: one link per service; every call that moves or commands it needs the token.
    @app.get("/api/v1/robot", tags=["robot"])
    def robot_status() -> dict:
        return robot.status()

    # The 3D view
    not_started = "the 3D view is not running (it starts with `parkour serve`)"

    def unavailable_reason() -> str:
        starter = app.state.view_starter
        return not_started if starter is None else starter.unavailable_reason

    def scene_view():
        view = None if app.state.view_starter is None else app.state.view_starter.view
        if view is None:
            raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, unavailable_reason())
        return view

    @app.get("/api/v1/view", response_model=schemas.ViewOut, tags=["view"])
    def view_info():
        """Where the 3D view is (its own port on this host) and what it shows."""
        try:
            return scene_view().info()
        except HTTPException:
            starting = app.state.view_starter is not None and app.state.view_starter.starting
            return {"available": False, "reason": unavailable_reason(), "starting": starting}

    @app.post("/api/v1/view/replay", dependencies=AUTHORIZED, response_model=schemas.ViewOut, tags=["view"])
    def view_replay(body: schemas.ViewReplay):
        """Show a stored run in the 3D view (replay mode), optionally with another as a ghost."""
        return scene_view().open_run(body.run_id, body.overlay_run_id)

    @app.get("/api/v1/runs/{run_id}/share.html", response_class=HTMLResponse, tags=["view"])
    def share_run(
        run_id: RecordId,
        overlay_run_id: Annotated[int | None, Query(ge=1, le=schemas.MAX_ID)] = None,
    ) -> HTMLResponse:
        """The run's 3D replay as one standalone HTML file: it plays offline, from disk, in any browser."""
        html = scene_view().share_html(run_id, overlay_run_id)
        disposition = f'attachment; filename="parkourlab-run-{run_id}.html"'
        return HTMLResponse(html, headers={"Content-Disposition": disposition})

    @app.websocket("/api/v1/robot/live")
    async def robot_live(
        websocket: WebSocket, rate: Annotated[float, Query(gt=0, le=50, description="messages per second")] = 20
    ):
        """Live state for the panel: link state, telemetry, the latest tracked pose, the run's
        newest touchdowns — ``rate`` messages per second until the client goes away."""
        await websocket.accept()
        try:
            while True:
                # Built from immutable snapshots under no lock that waits: on the event loop itself,
                # so a request pool full of compute cannot stall the live view.
                await websocket.send_json(robot.live())
                await asyncio.sleep(1.0 / rate)
        except (WebSocketDisconnect, RuntimeError):
            return

    @app.post("/api/v1/robot/connect", dependencies=AUTHORIZED, tags=["robot"])
    def robot_connect(body: schemas.RobotConnect) -> dict:
        return robot.connect(body)

    @app.post("/api/v1/robot/disconnect", dependencies=AUTHORIZED, tags=["robot"])
    def robot_disconnect() -> dict:
        return robot.disconnect()

    @app.post("/api/v1/robot/arm", dependencies=AUTHORIZED, tags=["robot"])
    def robot_arm() -> dict:
        return robot.arm()

    @app.post("/api/v1/robot/disarm", dependencies=AUTHORIZED, tags=["robot"])
    def robot_disarm() -> dict:
        return robot.disarm()

    @app.post("/api/v1/robot/reset", dependencies=AUTHORIZED, tags=["robot"])
    def robot_reset() -> dict:
        return robot.reset()

    # No token: stopping is always allowed (docs/service.md). Async and on the robot service's own
    # e-stop thread, so a request pool filled by compute cannot hold it back.
    @app.post("/api/v1/robot/estop", tags=["robot"])
    async def robot_estop() -> dict:
        """Emergency stop, at any moment and without the token; answers within 200 ms. A live run
        ends (and is stored). ``acknowledged`` says whether the robot confirmed it (``latency_ms``);
        if not (``reason``: link blocked or lost), the robot's 1 s watchdog disarms it."""
        return await robot.estop_now()

    @app.post("/api/v1/robot/runs", status_code=202, dependencies=AUTHORIZED, tags=["robot"])
    def robot_run(body: schemas.RobotRunCreate) -> dict:
        """Start a live run; it is stored as a run of kind robot when it ends (see GET /api/v1/robot)."""
        robot.start_run(body)
        return robot.status()

    @app.post("/api/v1/robot/runs/stop", dependencies=AUTHORIZED, tags=["robot"])
    def robot_run_stop() -> dict:
        return robot.stop_run()

    # Quick calls for the control panel: computed, not stored.
    @app.post("/api/v1/sim/map", tags=["simulate"])
    def sim_map(body: schemas.MapIn) -> dict:
        return simulation.map_orbit(body)

    @app.post("/api/v1/sim/trajectory", tags=["simulate"])
    def sim_trajectory(body: schemas.TrajectoryIn) -> dict:
        """The sampled path in wall coordinates (nondimensional), for drawing; not stored."""
        return simulation.trajectory_columns(body)

    @app.post("/api/v1/sim/fixed-point", tags=["simulate"])
    def sim_fixed_point(body: schemas.FixedPointIn) -> dict:
        return simulation.fixed_point(body)

    return app


def _experiment_out(db: Session, experiment) -> dict:
    return {
        "id": experiment.id,
        "name": experiment.name,
        "description": experiment.description,
        "notes": experiment.notes,
        "tags": experiment.tags,
        "created_at": experiment.created_at,
        "updated_at": experiment.updated_at,
        "runs": records.run_count(db, experiment.id),
    }


def _run_out(run, *, detail: bool = False) -> dict:
    out = {
        "id": run.id,
        "experiment_id": run.experiment_id,
        "kind": run.kind,
        "status": run.status,
        "created_at": run.created_at,
        "duration_s": run.duration_s,
        "code_version": run.code_version,
        "model": run.model,
        "controls": run.controls,
        "start_state": run.start_state,
        "jumps": run.jumps,
        "jumps_completed": run.jumps_completed,
        "failure_code": run.failure_code,
        "climb": run.climb,
        "tags": run.tags,
        "notes": run.notes,
        "has_trajectory": run.trajectory is not None,
    }
    if detail:
        out["results"] = run.results
    return out


def _job_out(job) -> dict:
    return {
        "id": job.id,
        "experiment_id": job.experiment_id,
        "kind": job.kind,
        "state": job.state,
        "total": job.total,
        "completed": job.completed,
        "progress": job.completed / job.total if job.total else 1.0,
        "error": job.error,
        "spec": job.spec,
        "created_at": job.created_at,
        "started_at": job.started_at,
        "finished_at": job.finished_at,
    }


def _finite(level: dict) -> dict:
    """JSON has no NaN: a level without trials yet reports mean 0 with trials 0."""
    mean = level["mean"]
    return level | {"mean": mean if mean == mean else 0.0}
