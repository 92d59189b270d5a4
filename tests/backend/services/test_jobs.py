"""The jobs service called directly: a stored job, listed, cancelled, its results summarised."""

import math

import pytest
from sqlalchemy import update

from backend.errors import NotFound
from backend.jobs.gaits import GaitSearchJobCreate
from backend.jobs.mjtf import MJTFJobCreate
from backend.schemas import JobState, LegIn
from backend.services import jobs
from backend.store.models import Experiment, Job, Trial
from tests.backend.services.jobs_helpers import SMALL


class _Runner:
    """Takes note of the jobs handed to it."""

    def __init__(self):
        self.submitted = []

    def submit(self, job_id: int) -> None:
        self.submitted.append(job_id)


def test_a_stored_job_counts_what_it_will_do(session):
    experiment = Experiment(name="mjtf")
    session.add(experiment)
    session.commit()
    mjtf = jobs.create_job(session, MJTFJobCreate(experiment_id=experiment.id, **SMALL))
    assert (mjtf.kind, mjtf.state, mjtf.total, mjtf.completed, mjtf.experiment_id) == ("mjtf", "queued", 20, 0, 1)
    assert mjtf.spec["zeta0s"] == [0.88, 0.94] and mjtf.spec["guess"] == {"xdot": -0.93, "ydot": -0.2}
    assert session.get(Job, mjtf.id).code_version and mjtf.started_at is None and mjtf.finished_at is None
    assert mjtf.progress == 0.0
    gaits = jobs.create_job(session, GaitSearchJobCreate(kind="gaits", controls=[LegIn(psi0_deg=30.0, zeta0=0.9)]))
    assert (gaits.kind, gaits.total) == ("gaits", 1), "studies count chunks, set when they run"
    with pytest.raises(NotFound, match="experiment 999"):
        jobs.create_job(session, MJTFJobCreate(experiment_id=999, **SMALL))
    with pytest.raises(NotFound, match="job 999"):
        jobs.get_job(session, 999)


def test_a_stored_job_is_handed_to_the_runner_once_committed(sessions, session):
    runner = _Runner()
    job = jobs.create_job(session, MJTFJobCreate(**SMALL), runner)
    assert runner.submitted == [job.id]
    with sessions() as other:  # the runner's thread reads it in a session of its own
        assert jobs.get_job(other, job.id).state == JobState.QUEUED


def test_jobs_list_by_state_newest_first(session):
    made = [jobs.create_job(session, MJTFJobCreate(**SMALL)).id for _ in range(3)]
    jobs.cancel_job(session, made[1])
    first = jobs.list_jobs(session, state=None, limit=2, cursor=None)
    assert [job.id for job in first.items] == made[:0:-1] and first.next_cursor == made[1]
    second = jobs.list_jobs(session, state=None, limit=2, cursor=first.next_cursor)
    assert [job.id for job in second.items] == made[:1] and second.next_cursor is None
    queued = jobs.list_jobs(session, state=JobState.QUEUED, limit=10, cursor=None)
    assert [job.id for job in queued.items] == [made[2], made[0]]


def test_summaries_of_a_job_without_trials(session):
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    for summary in jobs.level_summaries(session, job):
        assert summary["trials"] == 0 and math.isnan(summary["mean"]) and summary["std"] == 0.0
        assert sum(summary["outcomes"].values()) == 0
    results = jobs.job_results(session, job.id)
    assert results.partial and results.levels == [] and results.missing_zeta0s == SMALL["zeta0s"]


def test_results_sum_the_stored_trials_per_level(session):
    """Mean and sample std from the database's sums, the outcomes counted per failure."""
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    jumps = [3, 5, 10]
    session.add_all(
        Trial(job_id=job.id, level=0, index=k, zeta0=0.88, seed=k, jumps=n, failure_code=code)
        for k, (n, code) in enumerate(zip(jumps, ["slip", None, "slip"], strict=True))
    )
    session.execute(update(Job).where(Job.id == job.id).values(state="done", completed=3))
    session.commit()
    results = jobs.job_results(session, job.id)
    assert not results.partial and results.missing_zeta0s == [0.94]
    (level,) = results.levels
    assert (level.zeta0, level.trials) == (0.88, 3) and level.mean == pytest.approx(6.0, rel=1e-15)
    assert level.std == pytest.approx(math.sqrt(((3 - 6) ** 2 + (5 - 6) ** 2 + (10 - 6) ** 2) / 2), rel=1e-15)
    assert level.outcomes["slip"] == 2 and level.outcomes["capped"] == 1 and sum(level.outcomes.values()) == 3


def test_results_of_a_study_are_its_stored_result(session):
    job = jobs.create_job(session, GaitSearchJobCreate(kind="gaits", controls=[LegIn(psi0_deg=30.0, zeta0=0.9)]))
    assert jobs.job_results(session, job.id).result is None
    session.execute(update(Job).where(Job.id == job.id).values(state="done", result={"gaits": []}))
    session.commit()
    results = jobs.job_results(session, job.id)
    assert (results.partial, results.result, results.levels) == (False, {"gaits": []}, None)
