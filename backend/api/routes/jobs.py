"""Batch jobs of every registered kind (:mod:`backend.jobs`), queued and resumed across restarts."""

from __future__ import annotations

import asyncio
import json
import time
from typing import Annotated, Literal

from fastapi import APIRouter, Query, Request
from fastapi.encoders import jsonable_encoder
from fastapi.responses import StreamingResponse

from backend import schemas
from backend.api.deps import AUTHORIZED, Cursor, Db, PageLimit, RecordId, Runner, SubmittedVia, Who
from backend.jobs import BY_NAME, JobCreate
from backend.services import jobs

EVENT_POLL_S = 0.25  # progress comes from committed chunks; a quarter second is live enough

router = APIRouter(prefix="/api/v1/jobs", tags=["jobs"])
KindName = Literal[tuple(BY_NAME)]  # a registered kind's name: any other is a 422 naming the allowed ones


@router.post("", status_code=202, dependencies=AUTHORIZED, response_model=schemas.JobOut)
async def create_job(body: JobCreate, db: Db, runner: Runner, person: Who, via: SubmittedVia) -> schemas.JobOut:
    """Queue a job, as the token's person (``submitted_by``; ``X-Parkour-Client`` only labels the
    tool: ``submitted_via``). Past the queue's budget of work, or this person's share of it, a 429
    says what is queued (docs/service.md); ``queue_position`` and ``eta_s`` say where it stands."""
    return await db(jobs.create_job, body, runner, person=person, via=via)


@router.get("", response_model=schemas.JobPage)
async def list_jobs(
    db: Db,
    limit: PageLimit = 50,
    cursor: Cursor = None,
    state: schemas.JobState | None = None,
    experiment_id: Annotated[int | None, Query(ge=1, le=schemas.MAX_ID, description="only this experiment's")] = None,
    kind: Annotated[KindName | None, Query(description="only jobs of this kind")] = None,
    world_id: Annotated[
        int | None, Query(ge=1, le=schemas.MAX_ID, description="only jobs in this stored world")
    ] = None,
) -> schemas.JobPage:
    """Jobs, newest first, a keyset page at a time; each filter given narrows them (the panel's
    Robot tab asks for the finished ``plan`` jobs, say)."""
    only = {"state": state, "experiment_id": experiment_id, "kind": kind, "world_id": world_id}
    return await db(jobs.list_jobs, limit=limit, cursor=cursor, **only)


@router.get("/{job_id}", response_model=schemas.JobOut)
async def get_job(job_id: RecordId, db: Db) -> schemas.JobOut:
    return await db(jobs.get_job, job_id)


@router.get("/{job_id}/results", response_model=schemas.JobResults)
async def job_results(job_id: RecordId, db: Db) -> schemas.JobResults:
    return await db(jobs.job_results, job_id)


@router.get("/{job_id}/events", response_class=StreamingResponse)
async def job_events(
    job_id: RecordId,
    request: Request,
    timeout: Annotated[
        float, Query(gt=0, le=86_400, allow_inf_nan=False, description="close the stream after this many seconds")
    ] = 3600,
) -> StreamingResponse:
    """Server-sent events: a ``progress`` event whenever the job's state or count changes; the
    stream ends after the job's final state (done, cancelled, failed) or ``timeout``."""
    db = request.app.state.database
    first = await db(jobs.get_job, job_id)  # a missing job is a 404 before the stream opens

    async def stream():
        job, last, deadline = first, None, time.monotonic() + timeout
        while True:
            key = (job.state, job.completed)
            if key != last:
                last = key
                yield f"event: progress\ndata: {json.dumps(jsonable_encoder(job.model_dump()))}\n\n"
            if job.state in jobs.FINAL or time.monotonic() > deadline or await request.is_disconnected():
                return
            await asyncio.sleep(EVENT_POLL_S)
            job = await db(jobs.get_job, job_id)

    return StreamingResponse(stream(), media_type="text/event-stream", headers={"Cache-Control": "no-cache"})


@router.post("/{job_id}/cancel", dependencies=AUTHORIZED, response_model=schemas.JobOut)
async def cancel_job(job_id: RecordId, db: Db) -> schemas.JobOut:
    return await db(jobs.cancel_job, job_id)
