"""The jobs' and trials' SQL (backend/repositories/jobs.py) on a migrated SQLite file: conditional
state changes, recovery after a restart, stored trials by level, the per-level sums."""

import pytest

from backend.errors import NotFound
from backend.repositories import jobs as stored_jobs
from backend.schemas import JobState
from backend.store.models import Experiment, Job, Trial


def _job(session, state: JobState = JobState.QUEUED, **fields) -> Job:
    job = stored_jobs.add(session, Job(kind="mjtf", spec={}, state=state, total=4, code_version="test", **fields))
    session.commit()
    return job


def _state(session, job_id: int) -> str | None:
    return stored_jobs.state_of(session, job_id)


def test_a_job_is_found_by_id_or_named_as_missing(session):
    job = _job(session)
    assert stored_jobs.get(session, job.id) is job and stored_jobs.find(session, job.id) is job
    assert stored_jobs.find(session, 999) is None and _state(session, 999) is None
    with pytest.raises(NotFound, match="job 999"):
        stored_jobs.get(session, 999)


def test_a_state_changes_only_from_the_state_named(session):
    job = _job(session)
    assert stored_jobs.change_state(session, job.id, JobState.RUNNING, state=JobState.CANCELLING) == 0
    assert _state(session, job.id) == "queued"
    assert stored_jobs.change_state(session, job.id, JobState.QUEUED, state=JobState.CANCELLED) == 1
    session.commit()
    assert _state(session, job.id) == "cancelled"


def test_a_claim_takes_queued_and_interrupted_jobs_and_keeps_the_first_start(session):
    queued, cancelled = _job(session), _job(session, JobState.CANCELLED)
    assert stored_jobs.claim(session, queued.id) and not stored_jobs.claim(session, cancelled.id)
    session.commit()
    session.refresh(queued)
    first_start = queued.started_at
    assert queued.state == "running" and first_start is not None
    assert stored_jobs.claim(session, queued.id), "a job left running (the service died) is claimed again"
    session.commit()
    session.refresh(queued)
    assert queued.started_at == first_start and _state(session, cancelled.id) == "cancelled"


def test_after_a_restart_running_jobs_queue_again_and_cancelling_ones_are_cancelled(session):
    running, cancelling, queued = _job(session, JobState.RUNNING), _job(session, JobState.CANCELLING), _job(session)
    done = _job(session, JobState.DONE)
    stored_jobs.recover_interrupted(session)
    session.commit()
    assert [_state(session, job.id) for job in (running, cancelling, queued, done)] == [
        "queued",
        "cancelled",
        "queued",
        "done",
    ]
    session.refresh(cancelling)
    assert cancelling.finished_at is not None
    assert stored_jobs.queued_ids(session) == [running.id, queued.id], "oldest first"


def test_jobs_page_newest_first_by_state_and_experiment(session):
    experiment = Experiment(name="studies")
    session.add(experiment)
    session.commit()
    made = [_job(session), _job(session, experiment_id=experiment.id), _job(session, JobState.DONE)]
    rows, cursor = stored_jobs.newest(session, state=None, limit=2, cursor=None, experiment_id=None)
    assert [row.id for row in rows] == [made[2].id, made[1].id] and cursor == made[1].id
    rows, cursor = stored_jobs.newest(session, state=None, limit=2, cursor=cursor, experiment_id=None)
    assert [row.id for row in rows] == [made[0].id] and cursor is None
    rows, _ = stored_jobs.newest(session, state=JobState.QUEUED, limit=9, cursor=None, experiment_id=None)
    assert [row.id for row in rows] == [made[1].id, made[0].id]
    rows, _ = stored_jobs.newest(session, state=None, limit=9, cursor=None, experiment_id=experiment.id)
    assert [row.id for row in rows] == [made[1].id]


def _trial(job_id: int, level: int, index: int, jumps: int, code: str | None = None) -> Trial:
    return Trial(job_id=job_id, level=level, index=index, zeta0=0.9, seed=index, jumps=jumps, failure_code=code)


def test_stored_trials_count_into_the_job_and_are_listed_by_level(session):
    job, other = _job(session), _job(session)
    stored_jobs.add_trials(session, job.id, [_trial(job.id, 0, 0, 5), _trial(job.id, 1, 3, 7)])
    stored_jobs.add_trials(session, other.id, [_trial(other.id, 0, 1, 2)])
    session.commit()
    stored_jobs.add_trials(session, job.id, [_trial(job.id, 0, 2, 1)])
    session.commit()
    session.refresh(job)
    assert job.completed == 3, "the job's count is its stored trials, the earlier commit's included"
    assert stored_jobs.stored_indices(session, job.id) == {0: {0, 2}, 1: {3}}
    assert stored_jobs.stored_indices(session, _job(session).id) == {}


def test_outcomes_are_summed_per_level_and_failure(session):
    job = _job(session)
    trials = [(0, 4, None), (0, 6, None), (0, 3, "slip"), (1, 10, "collapse"), (1, 1, "collapse")]
    stored_jobs.add_trials(session, job.id, [_trial(job.id, lv, k, n, code) for k, (lv, n, code) in enumerate(trials)])
    session.commit()
    moments = sorted(stored_jobs.outcome_moments(session, job.id), key=lambda row: (row[0], row[1] or ""))
    assert moments == [(0, None, 2, 10, 52), (0, "slip", 1, 3, 9), (1, "collapse", 2, 11, 101)]
    assert all(type(value) is int for row in moments for value in row[2:])
