"""The jobs, their trials and their chunks in the store: SQL and only SQL (the services commit).

A job's state changes with conditional UPDATEs (:func:`change_state`, :func:`claim`): the job
runner and a cancel request may write the same row at once, and reading the state first and then
writing it could overwrite a state the other just wrote. A job's trials are summed per level and
outcome by the database (:func:`outcome_moments`), never read one by one.
"""

from __future__ import annotations

import datetime
from collections.abc import Iterable

from sqlalchemy import Text, cast, func, select, update
from sqlalchemy.orm import Session

from backend.repositories.common import fetch, newest_first, page
from backend.schemas.jobs import JobState
from backend.store.models import Job, JobChunk, Trial, utcnow

_UNSYNCHRONIZED = {"synchronize_session": False}  # a conditional UPDATE: the session's copy is refreshed after


def add(session: Session, job: Job) -> Job:
    session.add(job)
    return job


def get(session: Session, job_id: int) -> Job:
    """The job; :class:`~backend.errors.NotFound` if there is none."""
    return fetch(session, Job, job_id, "job")


def find(session: Session, job_id: int) -> Job | None:
    return session.get(Job, job_id)


def state_of(session: Session, job_id: int) -> str | None:
    """The job's state as committed (None if there is no such job)."""
    return session.scalar(select(Job.state).where(Job.id == job_id))


def newest(session: Session, *, limit: int, cursor: int | None, **only) -> tuple[list[Job], int | None]:
    """A keyset page of jobs, newest first, ``only`` those of the filters given (:func:`_of`)."""
    query = _of(newest_first(Job, limit, cursor), **only)
    return page(list(session.scalars(query)), limit)


def count(session: Session, **only) -> int:
    """How many jobs :func:`newest` pages through."""
    return session.scalar(_of(select(func.count()).select_from(Job), **only)) or 0


def _of(
    query,
    state: JobState | None = None,
    experiment_id: int | None = None,
    kind: str | None = None,
    world_id: int | None = None,
):
    """``query`` of the jobs in ``state``, filed under ``experiment_id``, of ``kind`` and in the
    stored world ``world_id``: each where given."""
    for column, value in (
        (Job.state, state),
        (Job.experiment_id, experiment_id),
        (Job.kind, kind),
        (Job.world_id, world_id),
    ):
        if value is not None:
            query = query.where(column == value)
    return query


def change_state(session: Session, job_id: int, was: JobState, **values) -> int:
    """Set ``values`` on the job if it is in state ``was``, in one UPDATE; the rows changed (0 or 1)."""
    changed = update(Job).where(Job.id == job_id, Job.state == was).values(**values)
    return session.execute(changed, execution_options=_UNSYNCHRONIZED).rowcount


def claim(session: Session, job_id: int) -> bool:
    """Mark a queued (or interrupted, still running) job running, its first start kept; whether it was."""
    claimed = (
        update(Job)
        .where(Job.id == job_id, Job.state.in_((JobState.QUEUED, JobState.RUNNING)))
        .values(state=JobState.RUNNING, started_at=func.coalesce(Job.started_at, utcnow()))
    )
    return bool(session.execute(claimed, execution_options=_UNSYNCHRONIZED).rowcount)


def recover_interrupted(session: Session) -> None:
    """After a restart: jobs left running are queued again, jobs left cancelling are cancelled."""
    session.execute(update(Job).where(Job.state == JobState.RUNNING).values(state=JobState.QUEUED))
    session.execute(
        update(Job).where(Job.state == JobState.CANCELLING).values(state=JobState.CANCELLED, finished_at=utcnow())
    )


# What the queue's room and standings read of each unfinished job, every submission: rows of these
# columns, the spec as its stored text (what it costs is worked out once per text: job_queue.py).
QUEUED_COLUMNS = (Job.id, Job.kind, Job.state, Job.total, Job.completed, Job.submitted_by,
                  cast(Job.spec, Text).label("spec"))  # fmt: skip


def unfinished(session: Session) -> list:
    """The jobs queued, running or cancelling, oldest first (the queue, bounded by its budget), as
    rows of :data:`QUEUED_COLUMNS` (``row.id``, ``row.spec``: JSON text ...)."""
    waiting = (JobState.QUEUED, JobState.RUNNING, JobState.CANCELLING)
    return list(session.execute(select(*QUEUED_COLUMNS).where(Job.state.in_(waiting)).order_by(Job.id)))


def done_mark(session: Session) -> tuple[int, int]:
    """``(count, newest id)`` of the jobs done: changes whenever one more is."""
    count, newest = session.execute(select(func.count(), func.max(Job.id)).where(Job.state == JobState.DONE)).one()
    return int(count), int(newest or 0)


def recent_done(session: Session, limit: int) -> list[tuple[str, dict, datetime.datetime, datetime.datetime]]:
    """``(kind, spec, started_at, finished_at)`` of the newest ``limit`` jobs done, newest first."""
    query = (select(Job.kind, Job.spec, Job.started_at, Job.finished_at)
             .where(Job.state == JobState.DONE, Job.started_at.is_not(None), Job.finished_at.is_not(None))
             .order_by(Job.id.desc()).limit(limit))  # fmt: skip
    return [tuple(row) for row in session.execute(query)]


def queued_ids(session: Session) -> list[int]:
    """The queued jobs' ids, oldest first."""
    return list(session.scalars(select(Job.id).where(Job.state == JobState.QUEUED).order_by(Job.id)))


def stored_indices(session: Session, job_id: int) -> dict[int, set[int]]:
    """The indices of the job's stored trials, by level (levels without any are absent)."""
    stored: dict[int, set[int]] = {}
    for level, index in session.execute(select(Trial.level, Trial.index).where(Trial.job_id == job_id)):
        stored.setdefault(level, set()).add(index)
    return stored


def add_trials(session: Session, job_id: int, trials: Iterable[Trial]) -> None:
    """Store trials of the job and count them into its ``completed`` (one transaction with the caller's commit)."""
    session.add_all(trials)
    session.flush()
    completed = session.scalar(select(func.count()).select_from(Trial).where(Trial.job_id == job_id))
    session.execute(update(Job).where(Job.id == job_id).values(completed=completed, updated_at=utcnow()))


def stored_chunks(session: Session, job_id: int) -> dict[int, dict]:
    """The chunked job's finished chunks: ``{chunk index: its JSON result}``."""
    rows = session.execute(select(JobChunk.index, JobChunk.result).where(JobChunk.job_id == job_id))
    return {index: result for index, result in rows}


def add_chunk(session: Session, job_id: int, index: int, result: dict) -> None:
    """Store one finished chunk and count it into the job's ``completed`` (one transaction with the
    caller's commit); a chunk stored already is an IntegrityError (the key refuses a second copy)."""
    session.add(JobChunk(job_id=job_id, index=index, result=result))
    session.flush()
    completed = session.scalar(select(func.count()).select_from(JobChunk).where(JobChunk.job_id == job_id))
    session.execute(update(Job).where(Job.id == job_id).values(completed=completed, updated_at=utcnow()))


def outcome_moments(session: Session, job_id: int) -> list[tuple[int, str | None, int, int, int]]:
    """Per level and failure code (None: capped): ``(level, code, trials, sum of jumps, sum of
    squares)``, in one GROUP BY. PostgreSQL sums integers as numeric: they come back as ints."""
    groups = session.execute(
        select(
            Trial.level, Trial.failure_code, func.count(), func.sum(Trial.jumps), func.sum(Trial.jumps * Trial.jumps)
        )
        .where(Trial.job_id == job_id)
        .group_by(Trial.level, Trial.failure_code)
    ).all()
    return [(level, code, int(trials), int(total), int(squares)) for level, code, trials, total, squares in groups]
