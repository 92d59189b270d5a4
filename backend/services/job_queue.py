"""The job queue: a budget of queued work, each person's share of it, and where each job stands.

Jobs run one at a time (:mod:`backend.services.job_runner`). What is queued and running is bounded
by :data:`~backend.schemas.job_budget.QUEUE_BUDGET_JUMPS` of work, each job counted at its worst
(:func:`~backend.jobs.worst_case_jumps`, each kind's own count; a running one by the share it has still to do), and
one person — the token's, whatever tools they submit through — may hold at most
:data:`~backend.schemas.job_budget.PERSON_SHARE` of it and have at most
:data:`~backend.schemas.job_budget.PERSON_QUEUED_JOBS` waiting, so one person's scripts cannot
starve another's panel. A job past any of these is refused with a 429
(:class:`~backend.errors.QueueFull`) saying what is queued.
A queued job's place is its rank among the queued jobs by id (the runner takes them oldest
first); its estimates are the time of the jobs ahead of it and its own: ``eta_s`` as expected on
this machine (:mod:`backend.services.job_estimates`), ``eta_max_s`` at the latest (every job at
its worst case, at the job worker's rate).
"""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable
from dataclasses import dataclass

from sqlalchemy.orm import Session

from backend.errors import QueueFull
from backend.jobs import UnreadableSpec, decode, worst_case_jumps
from backend.repositories import jobs as stored_jobs
from backend.schemas.job_budget import (
    JOB_RATE_JUMPS_PER_S,
    MAX_QUEUED_JOBS,
    PERSON_QUEUED_JOBS,
    PERSON_SHARE,
    QUEUE_BUDGET_JUMPS,
)
from backend.schemas.jobs import JobState
from backend.services import job_estimates
from backend.services.job_estimates import Paces
from backend.store.models import Job


@dataclass(frozen=True)
class Standing:
    """Where an unfinished job stands: ``position`` 1 runs next (None: running), ``eta_s`` the
    seconds until it should end (expected on this machine), ``eta_max_s`` until it ends at the latest."""

    position: int | None
    eta_s: float
    eta_max_s: float


def _share_left(job: Job) -> float:
    """The share of its work a job has still to do: all of it while queued, the share of its total
    not completed while running."""
    if job.state == JobState.QUEUED or not job.total:
        return 1.0
    return max(job.total - job.completed, 0) / job.total


def _measures(job: Job) -> tuple[int, str]:
    """A job's work at its worst [jumps] and its :func:`~backend.services.job_estimates.spec_key`;
    ``job.spec`` is the stored JSON text (:func:`~backend.repositories.jobs.unfinished`) or a dict."""
    text = job.spec if isinstance(job.spec, str) else json.dumps(job.spec, sort_keys=True)
    return _measures_of_text(job.kind, text)


@functools.lru_cache(maxsize=4096)
def _measures_of_text(kind: str, text: str) -> tuple[int, str]:
    # Once per spec text, not per job and request: each submission measures every unfinished job,
    # and decoding 300 queued specs twice took a submission from 2.5 to 15 ms (scripts/bench_job_submit.py).
    spec = json.loads(text)
    try:
        worst = worst_case_jumps(decode(spec))[0]
    except UnreadableSpec:
        worst = 0  # a spec of another version of the code: it will fail when it runs, taking no time
    return worst, job_estimates.spec_key(kind, spec)


def _worst(job: Job) -> int:
    return _measures(job)[0]


def work_left(job: Job) -> int:
    """The job's work still to do, in jumps at its worst."""
    return round(_worst(job) * _share_left(job))


def check_room(session: Session, body, person: str) -> list:
    """Refuse ``body`` (a job request) with :class:`QueueFull` if the queue, or ``person``'s share
    of it, has no room for its work at its worst, or ``person`` has as many jobs waiting as one may.
    Returns the unfinished jobs it read (rows of :func:`backend.repositories.jobs.unfinished`), so
    the new job's standing needs no second read of them."""
    unfinished = stored_jobs.unfinished(session)
    wanted, _ = worst_case_jumps(body)
    left = {job.id: work_left(job) for job in unfinished}
    queued = sum(left.values())
    waiting = sum(job.state == JobState.QUEUED for job in unfinished)
    mine = sum(left[job.id] for job in unfinished if job.submitted_by == person)
    my_waiting = sum(job.state == JobState.QUEUED and job.submitted_by == person for job in unfinished)
    share = int(PERSON_SHARE * QUEUE_BUDGET_JUMPS)
    ahead = f"{len(unfinished)} jobs unfinished, {_jumps(queued)} of work ({_hours(queued)})"
    if waiting >= MAX_QUEUED_JOBS:
        raise QueueFull(f"the job queue is full: {waiting} jobs wait, the most it holds; {ahead}. "
                        "Wait for some to finish, or cancel some")  # fmt: skip
    if queued + wanted > QUEUE_BUDGET_JUMPS:
        raise QueueFull(
            f"the job queue is full: this job's {_jumps(wanted)} at its worst would take the queue past its budget "
            f"of {_jumps(QUEUE_BUDGET_JUMPS)} ({_hours(QUEUE_BUDGET_JUMPS)}); {ahead}. "
            "Wait for jobs to finish, cancel some, or ask for less"
        )
    if my_waiting >= PERSON_QUEUED_JOBS:
        raise QueueFull(
            f"{person} has {my_waiting} jobs waiting, the most one person may, kept so others always find room; "
            f"{ahead}. Wait for your jobs to finish, or cancel some"
        )
    if mine + wanted > share:
        raise QueueFull(
            f"{person} already holds {_jumps(mine)} of queued work; with this job's {_jumps(wanted)} it would pass "
            f"a person's share of {_jumps(share)} ({_hours(share)}), kept so others always find room. "
            "Wait for your jobs to finish, or cancel some"
        )
    return unfinished


def standings(session: Session) -> dict[int, Standing]:
    """Every unfinished job's standing, by id (one query of the unfinished jobs, and of the done ones'
    count for the paces)."""
    return standings_of(stored_jobs.unfinished(session), job_estimates.paces(session))


def standings_of(unfinished: Iterable[Job], paces: Paces | None = None) -> dict[int, Standing]:
    """:func:`standings` from the unfinished jobs, oldest first, and this machine's ``paces`` (None:
    each kind's typical one)."""
    paces = Paces() if paces is None else paces
    unfinished = list(unfinished)
    measures = {job.id: _measures(job) for job in unfinished}

    def left(job: Job) -> tuple[float, float]:  # (expected, at the latest) [s] of what it has still to do
        share = _share_left(job)
        worst, key = measures[job.id]
        expected = share * paces.expected_seconds(job.kind, worst, key)
        # "At the latest" is never sooner than expected: a kind whose jumps cost more than the map's
        # (a closed loop's law) runs slower than the worker's rate on its worst case.
        return expected, max(share * worst / JOB_RATE_JUMPS_PER_S, expected)

    started = [job for job in unfinished if job.state != JobState.QUEUED]  # running (or cancelling)
    expected = sum(left(job)[0] for job in started)
    latest = sum(left(job)[1] for job in started)
    result = {job.id: Standing(None, expected, latest) for job in started}
    position = 0
    for job in unfinished:
        if job.state == JobState.QUEUED:
            position += 1
            more, most = left(job)
            expected, latest = expected + more, latest + most
            result[job.id] = Standing(position, expected, latest)
    return result


def _jumps(jumps: int) -> str:
    return f"{jumps:.3g} jumps"


def _hours(jumps: int) -> str:
    hours = jumps / JOB_RATE_JUMPS_PER_S / 3600
    return f"about {hours:.1f} h of the job worker" if hours >= 1 else f"about {hours * 60:.0f} min of the job worker"
