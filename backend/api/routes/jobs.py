"""Batch jobs: MJTF trials, sweeps, basins and gait searches, queued and resumed across restarts."""

from __future__ import annotations

import asyncio
import json
import time
from typing import Annotated

from fastapi import APIRouter, Query, Request
from fastapi.encoders import jsonable_encoder
from fastapi.responses import StreamingResponse
from sqlalchemy.orm import Session

from backend import schemas
from backend.api.deps import AUTHORIZED, Cursor, Db, PageLimit, RecordId, Runner
from backend.services import calibrations, jobs

EVENT_POLL_S = 0.25  # progress comes from committed chunks; a quarter second is live enough

router = APIRouter(prefix="/api/v1/jobs", tags=["jobs"])


@router.post("", status_code=202, dependencies=AUTHORIZED, response_model=schemas.JobOut)
async def create_job(body: schemas.JobCreate, db: Db, runner: Runner):
    job = await db(lambda session: job_out(jobs.create_job(session, calibrations.with_preset_resolved(session, body))))
    if runner is not None:
        runner.submit(job["id"])
    return job


@router.get("", response_model=schemas.JobPage)
async def list_jobs(
    db: Db,
    limit: PageLimit = 50,
    cursor: Cursor = None,
    state: schemas.JobState | None = None,
    experiment_id: Annotated[int | None, Query(ge=1, le=schemas.MAX_ID, description="only this experiment's")] = None,
):
    def page(session: Session) -> dict:
        rows, next_cursor = jobs.list_jobs(
            session, state=state, limit=limit, cursor=cursor, experiment_id=experiment_id
        )
        return {"items": [job_out(row) for row in rows], "next_cursor": next_cursor}

    return await db(page)


@router.get("/{job_id}", response_model=schemas.JobOut)
async def get_job(job_id: RecordId, db: Db):
    return await db(job_snapshot, job_id)


@router.get("/{job_id}/results", response_model=schemas.JobResults)
async def job_results(job_id: RecordId, db: Db):
    def read(session: Session) -> tuple:
        job = jobs.get_job(session, job_id)
        return job_out(job), job.result, jobs.level_summaries(session, job) if job.kind == "mjtf" else None

    job, result, summaries = await db(read)
    if summaries is None:
        return {"job": job, "partial": job["state"] != "done", "result": result}
    return {
        "job": job,
        "partial": job["state"] != "done",
        "levels": [level for level in summaries if level["trials"]],  # a level with trials has a mean
        "missing_zeta0s": [level["zeta0"] for level in summaries if not level["trials"]],
    }


@router.get("/{job_id}/events", response_class=StreamingResponse)
async def job_events(
    job_id: RecordId,
    request: Request,
    timeout: Annotated[
        float, Query(gt=0, le=86_400, allow_inf_nan=False, description="close the stream after this many seconds")
    ] = 3600,
):
    """Server-sent events: a ``progress`` event whenever the job's state or count changes; the
    stream ends after the job's final state (done, cancelled, failed) or ``timeout``."""
    db = request.app.state.database
    first = await db(job_snapshot, job_id)  # a missing job is a 404 before the stream opens

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
            job = await db(job_snapshot, job_id)

    return StreamingResponse(stream(), media_type="text/event-stream", headers={"Cache-Control": "no-cache"})


@router.post("/{job_id}/cancel", dependencies=AUTHORIZED, response_model=schemas.JobOut)
async def cancel_job(job_id: RecordId, db: Db):
    return await db(lambda session: job_out(jobs.cancel_job(session, job_id)))


def job_snapshot(session: Session, job_id: int) -> dict:
    return job_out(jobs.get_job(session, job_id))


def job_out(job) -> dict:
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
