"""Batch jobs: MJTF studies, energy sweeps, basins and gait searches that live in the database.

A job is a row; an MJTF job's trials are rows too, with the idempotent key ``(job, level, index)``.
This module is the jobs' records and rules — store one, list, read, cancel, summarise its results —
each call one unit of work that returns what the API answers (``schemas.JobOut``, ``JobPage``,
``JobResults``). Running them is :mod:`backend.services.job_runner`'s; the SQL is
:mod:`backend.repositories.jobs`'.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from sqlalchemy.orm import Session

from backend.jobs import decode, encode, job_kind, spec_of
from backend.repositories import jobs as stored_jobs
from backend.repositories.common import locked
from backend.schemas.jobs import JobOut, JobPage, JobResults, JobState, MJTFLevelOut
from backend.services import job_estimates
from backend.services.job_queue import Standing, check_room, standings, standings_of
from backend.services.presets import resolve_model, with_preset_resolved
from backend.services.provenance import current_code_version
from backend.services.worlds import world_in_l0
from backend.store.database import lock_for_write
from backend.store.models import Experiment, Job, utcnow
from sim_core.robustness.mjtf_plan import CAPPED, jump_statistics, no_outcomes

if TYPE_CHECKING:
    from backend.services.job_runner import JobRunner

FINAL = frozenset({JobState.DONE, JobState.CANCELLED, JobState.FAILED})  # a job in one of these never changes again


def create_job(
    session: Session, body, runner: JobRunner | None = None, *, person: str | None = None, via: str | None = None
) -> JobOut:
    """Store a job (any of :data:`backend.jobs.JOB_KINDS`, a stored preset resolved) submitted by
    ``person`` (through the tool ``via``) and hand it to ``runner``; MJTF totals count trials, other
    kinds chunks. The queue's room is checked under the write lock
    (:mod:`backend.services.job_queue`: a 429 past its budget or the person's share), and its
    experiment read under it (``locked``), so a concurrent delete of it waits for this commit (and
    then refuses: the experiment has a job) or has removed it first (404)."""
    body = with_preset_resolved(session, body)
    lock_for_write(session)
    ahead = check_room(session, body, person or "unknown")
    if body.experiment_id is not None:
        locked(session, Experiment, body.experiment_id, "experiment")
    spec = in_its_world(session, spec_of(body))  # stored as its own versioned record: backend/jobs/specs.py says why
    job = stored_jobs.add(
        session,
        Job(
            experiment_id=body.experiment_id,
            kind=spec.kind,
            spec=encode(spec),
            state=JobState.QUEUED,
            total=job_kind(spec.kind).total(spec),
            code_version=current_code_version(),
            submitted_by=person,
            submitted_via=via,
            world_id=getattr(spec, "world_id", None),
        ),
    )
    session.commit()
    if runner is not None:
        runner.submit(job.id)
    # Its standing among the jobs read under the write lock: the queue as it stood at its submission.
    return public(job, standings_of([*ahead, job], job_estimates.paces(session)).get(job.id))


def in_its_world(session: Session, spec):
    """``spec`` with its stored world copied in (its §8 JSON in ``l0``: the job reads no store; a
    404 if there is no such world), checked by its kind where the schema cannot (a goal within the
    world: a 422 naming the field)."""
    kind = job_kind(spec.kind)
    if getattr(spec, "world_id", None) is not None:
        spec = replace(spec, world=world_in_l0(session, spec.world_id, spec.model.preset))
    if kind.check is not None:
        kind.check(spec, resolve_model(None, spec.model.preset).robot)  # a stored preset is resolved already
    return spec


def get_job(session: Session, job_id: int) -> JobOut:
    job = stored_jobs.get(session, job_id)
    return public(job, standings(session).get(job_id) if job.state not in FINAL else None)


def list_jobs(session: Session, *, limit: int, cursor: int | None, **only) -> JobPage:
    """A page of jobs, newest first; ``only`` filters them (state, experiment_id, kind, world_id:
    each None for any)."""
    rows, next_cursor = stored_jobs.newest(session, limit=limit, cursor=cursor, **only)
    total = stored_jobs.count(session, **only)
    standing = standings(session) if any(row.state not in FINAL for row in rows) else {}
    return JobPage(items=[public(row, standing.get(row.id)) for row in rows], next_cursor=next_cursor, total=total)


def cancel_job(session: Session, job_id: int) -> JobOut:
    """Queued jobs stop at once; running ones before their next chunk. Finished jobs are left as they are.

    Each change is one conditional UPDATE, so a job that the runner finishes while this request
    runs stays finished (reading the state and then writing it could overwrite "done").
    """
    job = stored_jobs.get(session, job_id)
    stored_jobs.change_state(session, job_id, JobState.QUEUED, state=JobState.CANCELLED, finished_at=utcnow())
    stored_jobs.change_state(session, job_id, JobState.RUNNING, state=JobState.CANCELLING)
    session.commit()
    session.refresh(job)
    return public(job)


def job_results(session: Session, job_id: int) -> JobResults:
    """The job and its results so far: an MJTF job's levels with trials (and those without yet),
    another kind's result once done."""
    row = stored_jobs.get(session, job_id)
    job = public(row)
    partial = job.state != JobState.DONE
    if job.kind != "mjtf":
        return JobResults(job=job, partial=partial, result=row.result)
    summaries = level_summaries(session, job)
    return JobResults(
        job=job,
        partial=partial,
        levels=[MJTFLevelOut(**level) for level in summaries if level["trials"]],  # a level with trials has a mean
        missing_zeta0s=[level["zeta0"] for level in summaries if not level["trials"]],
    )


def level_summaries(session: Session, job) -> list[dict]:
    """Per level of the MJTF ``job`` (its ``id`` and stored ``spec``): trials so far, mean and
    standard deviation of jumps to failure, outcomes — counted and summed by the database (one
    GROUP BY), not by reading every trial; the statistics are sim_core's (``jump_statistics``)."""
    spec = decode(job.spec)
    counts = [no_outcomes() for _ in spec.zeta0s]
    sums = [[0, 0, 0] for _ in spec.zeta0s]  # trials, sum of jumps, sum of squares: exact integers
    for level, code, trials, total, squares in stored_jobs.outcome_moments(session, job.id):
        counts[level][CAPPED if code is None else code] += trials
        for k, value in enumerate((trials, total, squares)):
            sums[level][k] += value
    summaries = []
    for level, zeta0 in enumerate(spec.zeta0s):
        mean, std = jump_statistics(*sums[level])
        summaries.append(
            {"zeta0": zeta0, "trials": sums[level][0], "mean": mean, "std": std, "outcomes": counts[level]}
        )
    return summaries


def public(job: Job, standing: Standing | None = None) -> JobOut:
    """A job as the API gives it (its progress: the share of its work done; ``standing``: its place
    in the queue and estimate, while unfinished)."""
    return JobOut(
        id=job.id,
        experiment_id=job.experiment_id,
        world_id=job.world_id,
        kind=job.kind,
        state=job.state,
        total=job.total,
        completed=job.completed,
        progress=job.completed / job.total if job.total else 1.0,
        error=job.error,
        spec=job.spec,
        created_at=job.created_at,
        started_at=job.started_at,
        finished_at=job.finished_at,
        submitted_by=job.submitted_by,
        submitted_via=job.submitted_via,
        queue_position=None if standing is None else standing.position,
        eta_s=None if standing is None else standing.eta_s,
        eta_max_s=None if standing is None else standing.eta_max_s,
    )
