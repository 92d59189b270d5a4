"""The job runner: stored jobs taken to their end, resumed with only what is missing, cancelled,
failed, paused on a full disk."""

import math
import time

import numpy as np
import pytest
from sqlalchemy import delete, select, update

from backend.errors import NotFound
from backend.jobs.basin import BasinJobCreate
from backend.jobs.control_study import ControlStudyJobCreate
from backend.jobs.gaits import GaitSearchJobCreate
from backend.jobs.mjtf import MJTFJobCreate
from backend.schemas import LegIn, StateIn
from backend.services import job_runner, jobs, storage_waits
from backend.store.models import Job, Trial
from sim_core import get_preset
from sim_core.model.noise import NoiseModel
from sim_core.robustness.mjtf import mjtf_study
from tests.backend.services.jobs_helpers import CHUNK, GUESS, SMALL, WAIT_S, job_now, stored_trials, wait_until


@pytest.fixture
def runner(sessions, compute):
    runner = job_runner.JobRunner(sessions, compute.jobs, chunk_trials=CHUNK)
    yield runner
    runner.stop(timeout=WAIT_S)


def test_an_mjtf_job_runs_to_the_librarys_numbers(sessions, session, compute):
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    job_runner.JobRunner(sessions, compute.jobs, chunk_trials=CHUNK).run(job.id)
    done = job_now(sessions, job.id)
    assert (done.state, done.completed, done.total) == ("done", 20, 20)
    assert done.started_at is not None and done.finished_at >= done.started_at
    study = mjtf_study(
        get_preset("paper").to_model(), math.radians(30.0), SMALL["zeta0s"], noise=NoiseModel(),
        trials=SMALL["trials"], cap=SMALL["cap"], seed=SMALL["seed"], guess=(GUESS.xdot, GUESS.ydot),
    )  # fmt: skip
    trials = stored_trials(session, job.id)
    assert [(level, index) for level, index, *_ in trials] == [(lv, i) for lv in range(2) for i in range(10)]
    jumps = np.array([row[3] for row in trials]).reshape(2, 10)
    for level, (summary, expected) in enumerate(zip(jobs.level_summaries(session, done), study.levels, strict=True)):
        np.testing.assert_array_equal(jumps[level], expected.jumps, err_msg=f"level {level}")
        assert summary["zeta0"] == SMALL["zeta0s"][level] and summary["trials"] == 10
        assert summary["mean"] == pytest.approx(float(np.mean(expected.jumps)), rel=1e-12)
        assert summary["std"] == pytest.approx(float(np.std(expected.jumps, ddof=1)), rel=1e-12)
        assert summary["outcomes"] == expected.histogram()


def test_an_interrupted_job_resumes_with_only_the_missing_trials(sessions, session, runner, compute):
    """As after a crash: some chunks committed, the job left ``running``. The next start finishes
    it with exactly the trials asked for and the numbers an uninterrupted run gives."""
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    job_runner.JobRunner(sessions, compute.jobs, chunk_trials=CHUNK).run(job.id)
    uninterrupted = stored_trials(session, job.id)
    kept = session.scalars(select(Trial.id).where(Trial.job_id == job.id, Trial.index < CHUNK)).all()
    session.execute(delete(Trial).where(Trial.job_id == job.id, Trial.index >= CHUNK))
    session.execute(update(Job).where(Job.id == job.id).values(state="running", completed=2 * CHUNK, finished_at=None))
    session.commit()

    runner.start()  # finds the running job and queues it again
    resumed = wait_until(sessions, job.id, lambda j: j.state in jobs.FINAL)
    assert (resumed.state, resumed.completed) == ("done", 20)
    assert stored_trials(session, job.id) == uninterrupted, "none lost, none duplicated, the same seeds and jumps"
    still_there = session.scalars(select(Trial.id).where(Trial.job_id == job.id, Trial.index < CHUNK)).all()
    assert still_there == kept, "the committed chunks were not recomputed"


def test_a_job_left_cancelling_is_cancelled_at_start(sessions, session, runner):
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    session.execute(update(Job).where(Job.id == job.id).values(state="cancelling"))
    session.commit()
    runner.start()  # the runner's thread settles what the last stop left (a full disk must not hold up the start)
    stopped = wait_until(sessions, job.id, lambda now: now.state == "cancelled")
    assert stopped.finished_at is not None and stored_trials(session, job.id) == []


def test_cancel_a_queued_job_at_once_and_leave_a_finished_one(sessions, session, compute):
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    cancelled = jobs.cancel_job(session, job.id)
    assert cancelled.state == "cancelled" and cancelled.finished_at is not None
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    assert stored_trials(session, job.id) == [], "the runner skips a cancelled job"
    done = jobs.create_job(session, MJTFJobCreate(**(SMALL | {"trials": 1}))).id
    job_runner.JobRunner(sessions, compute.jobs).run(done)
    with sessions() as fresh:  # as a request would: its own session, reading the finished job
        assert jobs.cancel_job(fresh, done).state == "done"
    assert job_now(sessions, done).state == "done"
    with pytest.raises(NotFound):
        jobs.cancel_job(session, 999)


def test_cancel_racing_the_end_of_a_job_leaves_it_done(sessions, session, compute):
    """A cancel that read "running" before the runner finished must not write "cancelling" over "done"
    (it did: the job was then marked cancelled at the next start though all its trials were in)."""
    job = jobs.create_job(session, MJTFJobCreate(**(SMALL | {"trials": 1})))
    session.execute(update(Job).where(Job.id == job.id).values(state="running"))
    session.commit()
    with sessions() as request:
        read = jobs.get_job(request, job.id)  # the cancel request reads the job (held, as inside cancel_job) ...
        assert read.state == "running"
        job_runner.JobRunner(sessions, compute.jobs).run(job.id)  # ... the runner finishes it meanwhile ...
        jobs.cancel_job(request, job.id)  # ... and the cancel lands after
    assert job_now(sessions, job.id).state == "done"


def test_cancel_stops_a_running_job_between_chunks(sessions, session, runner):
    spec = MJTFJobCreate(zeta0s=[0.84, 0.86, 0.88], trials=3000, cap=2000, guess=StateIn(xdot=-0.93, ydot=0.2))
    job = jobs.create_job(session, spec)
    runner.start()
    runner.submit(job.id)
    wait_until(sessions, job.id, lambda j: j.completed >= CHUNK)
    with sessions() as other:
        assert jobs.cancel_job(other, job.id).state in ("cancelling", "cancelled")
    stopped = wait_until(sessions, job.id, lambda j: j.state in jobs.FINAL)
    assert stopped.state == "cancelled" and CHUNK <= stopped.completed < stopped.total
    assert len(stored_trials(session, job.id)) == stopped.completed, "progress counts the committed trials"


def test_a_study_job_stores_its_result(sessions, session, compute):
    spec = GaitSearchJobCreate(kind="gaits", controls=[LegIn(psi0_deg=30.0, zeta0=0.9)], grid=2)
    job = jobs.create_job(session, spec)
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    done = job_now(sessions, job.id)
    assert (done.state, done.completed, done.total) == ("done", 1, 1)
    result = jobs.job_results(session, job.id).result
    assert result["gaits"][0]["period"] == 1 and result["gaits"][0]["stable"]


def test_a_control_study_left_running_by_a_crash_is_computed_again_to_the_same_result(sessions, session, runner):
    """A control study is deterministic: the job a crash left ``running`` (its progress part way)
    is queued again at the next start and ends with the result an uninterrupted run gives."""
    spec = ControlStudyJobCreate(kind="control-study", controllers=["pid-pitch", "pid"], seeds=60, jumps=60)
    job = jobs.create_job(session, spec)
    job_runner.JobRunner(sessions, runner.pool).run(job.id)
    uninterrupted = jobs.job_results(session, job.id).result
    assert job_now(sessions, job.id).total == 4, "two controllers x two chunks of 50 seeds"
    session.execute(update(Job).where(Job.id == job.id).values(state="running", completed=1, result=None,
                                                               finished_at=None))  # fmt: skip
    session.commit()

    runner.start()
    resumed = wait_until(sessions, job.id, lambda j: j.state in jobs.FINAL)
    assert (resumed.state, resumed.completed, resumed.total) == ("done", 4, 4)
    result = jobs.job_results(session, job.id).result
    for entry in (*result["controllers"], *uninterrupted["controllers"]):
        entry.pop("us_per_jump")  # timed, so never the same twice
    assert result == uninterrupted and [entry["name"] for entry in result["controllers"]] == ["pid-pitch", "pid"]


def test_a_failing_job_is_recorded_and_the_runner_goes_on(sessions, session, runner):
    no_gait = BasinJobCreate(kind="basin", controls=[LegIn(psi0_deg=80.0, zeta0=0.9)], grid=4)
    failing = jobs.create_job(session, no_gait)
    after = jobs.create_job(session, MJTFJobCreate(**(SMALL | {"trials": 2})))
    runner.start()
    failed = wait_until(sessions, failing.id, lambda j: j.state in jobs.FINAL)
    assert failed.state == "failed" and failed.error.startswith("ParameterError: controls")
    assert wait_until(sessions, after.id, lambda j: j.state in jobs.FINAL).state == "done"


def test_the_runner_leaves_a_job_cancelled_before_it_starts_alone(sessions, session, compute):
    """The runner claims a job with a conditional UPDATE: a cancel that came first wins."""
    job = jobs.create_job(session, MJTFJobCreate(**(SMALL | {"trials": 1})))
    cancelled = jobs.cancel_job(session, job.id)
    assert cancelled.state == "cancelled"
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    after = job_now(sessions, job.id)
    assert (after.state, after.started_at, after.finished_at) == ("cancelled", None, cancelled.finished_at)
    assert stored_trials(session, job.id) == []


def test_a_stored_job_the_request_schema_now_refuses_still_resumes(sessions, session, compute):
    """Its spec is read as stored (backend/jobs/specs.py), not re-validated by today's request ranges."""
    from backend.jobs.mjtf import MJTFSpec
    from backend.jobs.specs import StateSpec, encode

    # Two levels at one zeta0: the request schema refuses that today (they must be distinct).
    spec = MJTFSpec(zeta0s=(0.9, 0.9), trials=3, cap=50, guess=StateSpec(-0.93, -0.2))
    with pytest.raises(ValueError, match="distinct"):
        MJTFJobCreate(**{k: v for k, v in encode(spec).items() if k != "version"})
    job = Job(kind="mjtf", spec=encode(spec), state="running", total=6, code_version="old")
    session.add(job)
    session.commit()
    job_runner.JobRunner(sessions, compute.jobs).run(job.id)
    assert job_now(sessions, job.id).state == "done" and len(stored_trials(session, job.id)) == 6


def test_cancel_stops_the_worker_mid_chunk(sessions, session, compute):
    """One chunk of 20,000 long trials (many seconds): a cancel during it stops the worker at once,
    commits nothing of it, and the next job gets a fresh worker."""
    runner = job_runner.JobRunner(sessions, compute.jobs, chunk_trials=20_000)
    job = jobs.create_job(session, MJTFJobCreate(zeta0s=[0.9], trials=20_000, cap=20_000, seed=1, guess=GUESS))
    runner.start()
    try:
        runner.submit(job.id)
        wait_until(sessions, job.id, lambda j: j.state == "running")
        time.sleep(0.5)  # the chunk is in the worker
        restarts, cancelled_at = compute.jobs.restarts, time.monotonic()
        jobs.cancel_job(session, job.id)
        stopped = wait_until(sessions, job.id, lambda j: j.state in jobs.FINAL)
        took = time.monotonic() - cancelled_at
        assert stopped.state == "cancelled" and stopped.completed == 0 and stored_trials(session, job.id) == []
        # Stopped, not waited for: the runner stopped the worker (a chunk left to end would not be).
        # How soon is the machine's to say (the runner looks every 0.2 s); wait_until bounds a hang.
        assert compute.jobs.restarts == restarts + 1, "the cancel stopped the worker mid-chunk"
        print(f"cancelled mid-chunk in {took * 1000:.0f} ms")
        small = jobs.create_job(session, MJTFJobCreate(**(SMALL | {"trials": 2})))
        runner.submit(small.id)
        assert wait_until(sessions, small.id, lambda j: j.state in jobs.FINAL).state == "done"
    finally:
        runner.stop(timeout=WAIT_S)


def test_a_job_pauses_on_a_full_disk_and_goes_on_when_there_is_room(sessions, session, compute, monkeypatch, caplog):
    """Its chunks' results wait in memory while the disk is full (here: the first two commits
    fail as SQLite fails on a full disk), and are committed once there is room: no trial lost."""
    from backend.store.database import StorageFull

    monkeypatch.setattr(storage_waits, "STORAGE_RETRY", 0.05)
    commit, failures = job_runner.JobRunner._commit_chunk, []

    def full_twice(runner, *args):
        if len(failures) < 2:
            failures.append(args[0])
            raise StorageFull("INSERT INTO trials", {}, Exception("database or disk is full"))
        return commit(runner, *args)

    monkeypatch.setattr(job_runner.JobRunner, "_commit_chunk", full_twice)
    job = jobs.create_job(session, MJTFJobCreate(**SMALL))
    job_runner.JobRunner(sessions, compute.jobs, chunk_trials=CHUNK).run(job.id)
    done = job_now(sessions, job.id)
    assert (done.state, done.completed, len(failures)) == ("done", 20, 2)
    assert len(stored_trials(session, job.id)) == 20 and "paused" in caplog.text and "goes on" in caplog.text


def test_a_stopping_service_leaves_the_running_job_to_resume_and_starts_no_other(sessions, session, compute):
    """Issue 40: stopped mid-chunk, the runner ended only at stop()'s timeout, the job worker's end
    failed the running job, and the queued one then started a fresh worker that outlived the
    service. Now stop() returns within a look or two, the running job stays running (the next start
    resumes it) and the queued one stays queued."""
    runner = job_runner.JobRunner(sessions, compute.jobs, chunk_trials=20_000)
    long_job = jobs.create_job(session, MJTFJobCreate(zeta0s=[0.9], trials=20_000, cap=20_000, seed=1, guess=GUESS))
    queued = jobs.create_job(session, MJTFJobCreate(**SMALL))
    runner.start()
    try:
        runner.submit(long_job.id)
        runner.submit(queued.id)
        wait_until(sessions, long_job.id, lambda j: j.state == "running")
        time.sleep(0.5)  # the chunk is in the worker
        asked = time.monotonic()
        runner.stop(timeout=WAIT_S)
        took = time.monotonic() - asked
        assert not runner.thread.is_alive() and took < 5.0, f"stop took {took:.1f} s (the runner looks every 0.2 s)"
        assert job_now(sessions, long_job.id).state == "running", "left for the next start to resume"
        assert job_now(sessions, queued.id).state == "queued"
    finally:
        compute.jobs.restart("the test's long chunk")  # the service stops its pools after the runner
