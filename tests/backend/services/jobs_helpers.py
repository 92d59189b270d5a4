"""What the jobs' tests share: a small MJTF job, its trials as stored, and waiting for the runner."""

import time

from sqlalchemy import select

from backend.schemas import StateIn
from backend.services import jobs
from backend.store.models import Trial

GUESS = StateIn(xdot=-0.93, ydot=-0.2)
SMALL = {"zeta0s": [0.88, 0.94], "trials": 10, "cap": 200, "seed": 5, "guess": GUESS}
CHUNK = 4  # trials per commit in these tests: several chunks per level
# [s] an upper bound on waits for the background thread, not a timing assertion: the job workers run
# at niceness +10 (backend/workers/pools.py), about a tenth of a core beside busy programs of their own
WAIT_S = 300.0


def stored_trials(session, job_id: int) -> list[tuple[int, int, int, int]]:
    """``(level, index, seed, jumps)`` of a job's trials, in order."""
    rows = session.execute(
        select(Trial.level, Trial.index, Trial.seed, Trial.jumps).where(Trial.job_id == job_id)
        .order_by(Trial.level, Trial.index)
    ).all()  # fmt: skip
    return [tuple(row) for row in rows]


def job_now(sessions, job_id: int):
    """The job as a request would read it now (its own session)."""
    with sessions() as session:
        return jobs.get_job(session, job_id)


def wait_until(sessions, job_id: int, condition):
    deadline = time.monotonic() + WAIT_S
    while not condition(job := job_now(sessions, job_id)):
        assert time.monotonic() < deadline, f"job {job_id} is {job.state} with {job.completed} of {job.total}"
        time.sleep(0.02)
    return job
