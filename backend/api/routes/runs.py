"""Runs: stored, listed with filters and pages, exported, compared, aggregated, replayed."""

from __future__ import annotations

import functools
import io
from typing import Annotated

from fastapi import APIRouter, Query, Request
from fastapi.responses import Response, StreamingResponse
from pydantic import Field
from sqlalchemy.orm import Session

from backend import schemas
from backend.api.deps import (
    AUTHORIZED,
    Cursor,
    Db,
    PageLimit,
    PresetQuery,
    QuickCompute,
    Reads,
    RecordId,
    RunQuery,
    preset_resolved,
)
from backend.services import calibrations, mcap_export, records, simulation
from backend.services.robot_records import replay_run

router = APIRouter(prefix="/api/v1/runs", tags=["runs"])


class McapResponse(Response):
    media_type = "application/octet-stream"  # MCAP has no registered media type


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail)
async def create_run(body: schemas.RunCreate, request: Request, db: Db, compute: QuickCompute):
    """Simulate (in the quick compute worker) and store a run. The simulation is awaited, so no
    request thread waits for it; the database work before and after takes one briefly."""
    body = await preset_resolved(request, body)
    if body.experiment_id is not None:  # it exists: checked before the simulation is paid for
        await db(records.check_run_request, body)
    record = await compute.call(simulation.simulate_run, body)
    return await db(lambda session: run_out(records.store_run(session, body, record), detail=True))


@router.get("", response_model=schemas.RunPage)
async def list_runs(
    reads: Reads,
    where: RunQuery,
    limit: PageLimit = 50,
    cursor: Cursor = None,
    sort: Annotated[str, Query(pattern=f"^({'|'.join(records.SORTS)})$", description="-climb: best first")] = "-id",
    offset: Annotated[int, Query(ge=0, le=10_000_000, description="for sorts other than id")] = 0,
):
    """Runs matching the filters. Sorted by id, ``next_cursor`` pages by keyset; sorted by another
    field, pass ``next_cursor`` back as ``offset``. Read and encoded in a worker process
    (services/store_reads.py): the service's own process only forwards the page."""
    page = await reads.runs_page(where, limit=limit, cursor=cursor, sort=sort, offset=offset)
    return Response(page, media_type="application/json")


@router.get("/export", response_class=StreamingResponse)
async def export_runs(
    reads: Reads, where: RunQuery, format_: Annotated[str, Query(alias="format", pattern="^(csv|json)$")] = "csv"
):
    """Every run matching the filters when the export began, streamed, with tags, timings and
    parameters (not the path); read and encoded by the read workers, a part of 1000 runs at a time."""
    plan = await reads.export_plan(where, format_)
    body = reads.export_text(where, plan)
    media = "text/csv" if format_ == "csv" else "application/json"
    disposition = {"Content-Disposition": f'attachment; filename="runs.{format_}"'}
    return StreamingResponse(body, media_type=media, headers=disposition)


@router.get("/compare", response_model=schemas.RunComparison)
async def compare_runs(
    db: Db,
    ids: Annotated[
        list[Annotated[int, Field(ge=1, le=schemas.MAX_ID)]],
        Query(min_length=2, max_length=records.MAX_COMPARE, description="run ids"),
    ],
    only_differences: bool = True,
):
    """Runs side by side as flat fields; by default only the fields whose values differ."""
    return await db(records.compare_runs, ids, only_differences=only_differences)


@router.get("/aggregate", response_model=schemas.RunAggregate)
async def aggregate_runs(
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
    return {"by": by, "bins": bins, "groups": await db(records.aggregate_runs, where, by, bins)}


@router.get("/{run_id}", response_model=schemas.RunDetail)
async def get_run(run_id: RecordId, db: Db):
    return await db(lambda session: run_out(records.get_run(session, run_id), detail=True))


@router.get("/{run_id}/trajectory", response_model=schemas.RunTrajectory)
async def get_trajectory(run_id: RecordId, db: Db) -> Response:
    """The run's sampled path, column by column. Encoded in the request thread: a long run's path
    is megabytes of JSON, kept off the event loop that the e-stop shares."""
    return Response(await db(trajectory_json, run_id), media_type="application/json")


# A simulated run's path is nondimensional (docs/model.md §1); a robot or replay run's is the tracker's frames.
SIMULATED_UNITS = {"time": "sqrt(l0/g)", "x": "l0", "y": "l0", "foot_x": "l0", "foot_y": "l0", "psi": "rad",
                   "zeta": "l0", "phase": "0 stance, 1 flight", "jump": "index"}  # fmt: skip
RECORDED_UNITS = {"time": "s", "x": "m", "y": "m", "pitch": "rad"}


def trajectory_json(session: Session, run_id: int) -> bytes:
    run = records.get_run(session, run_id)
    if run.trajectory is None:
        raise records.NotFound("trajectory of run", run_id)
    columns = simulation.unpack_trajectory(run.trajectory)
    listed = {name: values.tolist() for name, values in columns.items()}
    units, table = ("nondimensional", SIMULATED_UNITS) if run.kind == "sim" else ("SI", RECORDED_UNITS)
    column_units = {name: table.get(name, "") for name in listed}
    return schemas.RunTrajectory(units=units, column_units=column_units, columns=listed).model_dump_json().encode()


@router.get("/{run_id}/export.mcap", response_class=McapResponse)
async def export_mcap(run_id: RecordId, db: Db) -> McapResponse:
    """A robot or replay run as an MCAP recording, which Foxglove and Rerun open: tracker poses,
    touchdowns, commands, telemetry, link changes and the model's prediction (docs/service.md).
    A simulated or still running run is a 409."""
    stream = io.BytesIO()
    await db(mcap_export.export_run, run_id, stream)
    disposition = f'attachment; filename="parkourlab-run-{run_id}.mcap"'
    return McapResponse(stream.getvalue(), headers={"Content-Disposition": disposition})


@router.get("/{run_id}/touchdowns", response_model=schemas.TouchdownComparison)
async def touchdown_predictions(run_id: RecordId, db: Db, compute: QuickCompute, preset: PresetQuery = None):
    """A robot or replay run's touchdowns as measured beside the paper's model's one-jump prediction
    of each and, with ``preset`` (a stored calibration), the calibrated model's, with residuals."""
    predict = functools.partial(compute.run, calibrations.predict_touchdowns)
    return await db(calibrations.touchdown_predictions, run_id, preset=preset, predict=predict)


@router.post("/{run_id}/replay", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail)
async def replay(run_id: RecordId, db: Db):
    """Analyse a robot run's recorded tracker frames again, stored as a run of kind replay."""
    return await db(lambda session: run_out(replay_run(session, run_id), detail=True))


@router.patch("/{run_id}", dependencies=AUTHORIZED, response_model=schemas.RunOut)
async def update_run(run_id: RecordId, body: schemas.RunUpdate, db: Db):
    return await db(lambda session: run_out(records.update_run(session, run_id, tags=body.tags, notes=body.notes)))


@router.delete("/{run_id}", status_code=204, dependencies=AUTHORIZED)
async def delete_run(run_id: RecordId, db: Db) -> None:
    await db(records.delete_run, run_id)


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
