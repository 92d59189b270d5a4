"""Runs: stored, listed with filters and pages, exported, compared, aggregated, replayed."""

from __future__ import annotations

import functools
import io
from typing import Annotated

from fastapi import APIRouter, Query
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
    Reads,
    RecordId,
    RunQuery,
    Who,
)
from backend.services import calibrations, mcap_export, robot_records
from backend.services import runs as service

router = APIRouter(prefix="/api/v1/runs", tags=["runs"])


class McapResponse(Response):
    media_type = "application/octet-stream"  # MCAP has no registered media type


@router.post("", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail)
async def create_run(body: schemas.RunCreate, db: Db, compute: QuickCompute, person: Who) -> schemas.RunDetail:
    """Simulate (in the quick compute worker) and store a run, made by the token's person
    (``created_by``). The simulation is awaited, so no request thread waits for it; the database
    work before and after takes one briefly."""
    return await service.create(db, compute, body, person=person)


@router.get("", response_model=schemas.RunPage)
async def list_runs(
    reads: Reads,
    where: RunQuery,
    limit: PageLimit = 50,
    cursor: Cursor = None,
    sort: Annotated[
        str, Query(pattern=f"^({'|'.join(service.SORTS)})$", description="a column; -climb: best first")
    ] = "-id",
    offset: Annotated[int, Query(ge=0, le=10_000_000, description="runs to skip (without a cursor)")] = 0,
) -> Response:
    """Runs matching the filters, with ``total``, how many match in all. Sorted by id,
    ``next_cursor`` pages by keyset; sorted by another field, pass ``next_cursor`` back as
    ``offset``; any page can be asked for by ``offset``. Ties on the sorted field are in id order.
    Read and encoded in a worker process (backend/workers/store_reads.py): the service's own
    process only forwards the page."""
    page = await reads.runs_page(where, limit=limit, cursor=cursor, sort=sort, offset=offset)
    return Response(page, media_type="application/json")


@router.get("/export", response_class=StreamingResponse)
async def export_runs(
    reads: Reads, where: RunQuery, format_: Annotated[str, Query(alias="format", pattern="^(csv|json)$")] = "csv"
) -> StreamingResponse:
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
        Query(min_length=2, max_length=service.MAX_COMPARE, description="run ids"),
    ],
    only_differences: bool = True,
) -> schemas.RunComparison:
    """Runs side by side as flat fields; by default only the fields whose values differ."""
    return await db(service.compare, ids, only_differences=only_differences)


@router.get("/aggregate", response_model=schemas.RunAggregate)
async def aggregate_runs(
    db: Db,
    where: RunQuery,
    by: Annotated[str, Query(pattern=f"^({'|'.join(service.GROUP_BY)})$")] = "zeta0",
    bins: Annotated[
        int | None,
        Query(ge=1, le=service.MAX_BINS, description="continuous parameters: equal bins over their range"),
    ] = None,
) -> schemas.RunAggregate:
    """Runs grouped by a parameter or tag: count, mean, std, min and max of climb and jumps completed.
    A continuous parameter (zeta0, psi0_deg, alpha) groups by exact value — at most 1000 — or in
    ``bins`` equal bins (each group then has ``low`` and ``high``)."""
    return await db(service.aggregate, where, by, bins)


@router.get("/{run_id}", response_model=schemas.RunDetail)
async def get_run(run_id: RecordId, db: Db) -> schemas.RunDetail:
    return await db(service.get, run_id)


@router.get("/{run_id}/trajectory", response_model=schemas.RunTrajectory)
async def get_trajectory(run_id: RecordId, db: Db) -> Response:
    """The run's sampled path, column by column. Encoded in the request thread: a long run's path
    is megabytes of JSON, kept off the event loop that the e-stop shares."""
    return Response(await db(service.trajectory_json, run_id), media_type="application/json")


@router.get("/{run_id}/export.mcap", response_class=McapResponse)
async def export_mcap(run_id: RecordId, db: Db) -> McapResponse:
    """A run as an MCAP recording, which Foxglove and Rerun open (docs/service.md): a robot or replay
    run's tracker poses, touchdowns, commands, telemetry, link changes and the model's prediction; a
    simulated run's stored path and touchdowns on the same channels. A run still running, a replay
    whose source is gone, or a simulated run stored without its path is a 409."""
    stream = io.BytesIO()
    await db(mcap_export.export_run, run_id, stream)
    disposition = f'attachment; filename="parkourlab-run-{run_id}.mcap"'
    return McapResponse(stream.getvalue(), headers={"Content-Disposition": disposition})


@router.get("/{run_id}/touchdowns", response_model=schemas.TouchdownComparison)
async def touchdown_predictions(
    run_id: RecordId, db: Db, compute: QuickCompute, preset: PresetQuery = None
) -> schemas.TouchdownComparison:
    """A robot or replay run's touchdowns as measured beside the paper's model's one-jump prediction
    of each and, with ``preset`` (a stored calibration), the calibrated model's, with residuals."""
    predict = functools.partial(compute.run, calibrations.predict_touchdowns)
    return await db(calibrations.touchdown_predictions, run_id, preset=preset, predict=predict)


@router.post("/{run_id}/replay", status_code=201, dependencies=AUTHORIZED, response_model=schemas.RunDetail)
async def replay(run_id: RecordId, db: Db, person: Who) -> schemas.RunDetail:
    """Analyse a robot run's recorded tracker frames again, stored as a run of kind replay."""
    return await db(robot_records.replay, run_id, person=person)


@router.patch("/{run_id}", dependencies=AUTHORIZED, response_model=schemas.RunOut)
async def update_run(run_id: RecordId, body: schemas.RunUpdate, db: Db, person: Who) -> schemas.RunOut:
    return await db(service.update, run_id, tags=body.tags, notes=body.notes, person=person)


@router.delete("/{run_id}", status_code=204, dependencies=AUTHORIZED)
async def delete_run(run_id: RecordId, db: Db) -> None:
    await db(service.delete, run_id)
