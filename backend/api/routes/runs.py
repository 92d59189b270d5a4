"""Runs: stored, listed with filters and pages, exported, compared, aggregated, replayed."""

from __future__ import annotations

import functools
import io
from typing import Annotated

from fastapi import APIRouter, Query, Request
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import Response, StreamingResponse
from pydantic import Field

from backend import schemas
from backend.api.deps import (
    AUTHORIZED,
    Cursor,
    Db,
    PageLimit,
    PresetQuery,
    QuickCompute,
    RecordId,
    RunQuery,
    preset_resolved,
    request_session,
)
from backend.services import calibrations, exports, mcap_export, records, simulation
from backend.services.robot_records import replay_run

router = APIRouter(prefix="/api/v1/runs", tags=["runs"])


class McapResponse(Response):
    media_type = "application/octet-stream"  # MCAP has no registered media type


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail)
async def create_run(body: schemas.RunCreate, request: Request, compute: QuickCompute):
    """Simulate (in the quick compute worker) and store a run. Async: the simulation is awaited, so
    no request thread waits for it; the database work before and after takes one briefly."""
    sessions = request.app.state.sessions
    body = await preset_resolved(request, body)

    def check() -> None:
        with request_session(sessions) as session:
            records.check_run_request(session, body)

    def store(record) -> dict:
        with request_session(sessions) as session:
            return run_out(records.store_run(session, body, record), detail=True)

    await run_in_threadpool(check)
    record = await compute.call(simulation.simulate_run, body)
    return await run_in_threadpool(store, record)


@router.get("", response_model=schemas.RunPage)
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
    return {"items": rows, "next_cursor": next_cursor}


@router.get("/export", response_class=StreamingResponse)
def export_runs(
    request: Request, where: RunQuery, format_: Annotated[str, Query(alias="format", pattern="^(csv|json)$")] = "csv"
):
    """Every run matching the filters, streamed, with tags, timings and parameters (not the path)."""
    body = exports.export(request.app.state.sessions, where, format_)
    media = "text/csv" if format_ == "csv" else "application/json"
    disposition = {"Content-Disposition": f'attachment; filename="runs.{format_}"'}
    return StreamingResponse(body, media_type=media, headers=disposition)


@router.get("/compare", response_model=schemas.RunComparison)
def compare_runs(
    db: Db,
    ids: Annotated[
        list[Annotated[int, Field(ge=1, le=schemas.MAX_ID)]],
        Query(min_length=2, max_length=records.MAX_COMPARE, description="run ids"),
    ],
    only_differences: bool = True,
):
    """Runs side by side as flat fields; by default only the fields whose values differ."""
    return records.compare_runs(db, ids, only_differences=only_differences)


@router.get("/aggregate", response_model=schemas.RunAggregate)
def aggregate_runs(
    db: Db,
    where: RunQuery,
    by: Annotated[str, Query(pattern=f"^({'|'.join(records.GROUP_BY)})$")] = "zeta0",
    bins: Annotated[
        int | None,
        Query(ge=1, le=records.MAX_BINS, description="continuous parameters: equal bins over their range"),
    ] = None,
):
    """Runs grouped by a parameter or tag: count, mean, std, min and max of climb and jumps completed.
    A continuous parameter (zeta0, psi0_deg, alpha) groups by exact value — at most 1000 — or in
    ``bins`` equal bins (each group then has ``low`` and ``high``)."""
    return {"by": by, "bins": bins, "groups": records.aggregate_runs(db, where, by, bins)}


@router.get("/{run_id}", response_model=schemas.RunDetail)
def get_run(run_id: RecordId, db: Db):
    return run_out(records.get_run(db, run_id), detail=True)


@router.get("/{run_id}/trajectory", response_model=schemas.RunTrajectory)
def get_trajectory(run_id: RecordId, db: Db):
    run = records.get_run(db, run_id)
    if run.trajectory is None:
        raise records.NotFound("trajectory of run", run_id)
    columns = simulation.unpack_trajectory(run.trajectory)
    return {"units": "nondimensional", "columns": {name: values.tolist() for name, values in columns.items()}}


@router.get("/{run_id}/export.mcap", response_class=McapResponse)
def export_mcap(run_id: RecordId, db: Db) -> McapResponse:
    """A robot or replay run as an MCAP recording, which Foxglove and Rerun open: tracker poses,
    touchdowns, commands, telemetry, link changes and the model's prediction (docs/service.md).
    A simulated or still running run is a 409."""
    stream = io.BytesIO()
    mcap_export.export_run(db, run_id, stream)
    disposition = f'attachment; filename="parkourlab-run-{run_id}.mcap"'
    return McapResponse(stream.getvalue(), headers={"Content-Disposition": disposition})


@router.get("/{run_id}/touchdowns", response_model=schemas.TouchdownComparison)
def touchdown_predictions(run_id: RecordId, db: Db, compute: QuickCompute, preset: PresetQuery = None):
    """A robot or replay run's touchdowns as measured beside the paper's model's one-jump prediction
    of each and, with ``preset`` (a stored calibration), the calibrated model's, with residuals."""
    return calibrations.touchdown_predictions(
        db, run_id, preset=preset, predict=functools.partial(compute.run, calibrations.predict_touchdowns)
    )


@router.post("/{run_id}/replay", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail)
def replay(run_id: RecordId, db: Db):
    """Analyse a robot run's recorded tracker frames again, stored as a run of kind replay."""
    return run_out(replay_run(db, run_id), detail=True)


@router.patch("/{run_id}", dependencies=AUTHORIZED, response_model=schemas.RunOut)
def update_run(run_id: RecordId, body: schemas.RunUpdate, db: Db):
    return run_out(records.update_run(db, run_id, tags=body.tags, notes=body.notes))


@router.delete("/{run_id}", status_code=204, dependencies=AUTHORIZED)
def delete_run(run_id: RecordId, db: Db) -> None:
    records.delete_run(db, run_id)


def run_out(run, *, detail: bool = False) -> dict:
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
        "has_trajectory": run.has_trajectory,
    }
    if detail:
        out["results"] = run.results
    return out
