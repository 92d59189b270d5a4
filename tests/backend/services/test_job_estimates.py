"""What a job should take on this machine (backend/services/job_estimates.py): each kind's pace,
learned from its newest done jobs (their times set here: a clock the test controls), the kind's
typical one before any, and a queue's expectations from them."""

from __future__ import annotations

import datetime

import pytest
from sqlalchemy import update

from backend.jobs import job_kind, worst_case_jumps
from backend.jobs.mjtf import MJTFJobCreate
from backend.jobs.viability import ViabilityJobCreate
from backend.schemas.job_budget import JOB_RATE_JUMPS_PER_S
from backend.services import job_estimates, jobs
from backend.services.job_estimates import OVERHEAD_S, Paces, learned_paces
from backend.store.models import Job
from tests.backend.services.jobs_helpers import SMALL

T0 = datetime.datetime(2026, 12, 6, 12, 0, 0)
WORK = worst_case_jumps(MJTFJobCreate(**SMALL))[0]
LARGE = SMALL | {"trials": 100, "cap": 10_000}  # 2e6 jumps at its worst: 15 s at the worker's rate
LARGE_WORK = worst_case_jumps(MJTFJobCreate(**LARGE))[0]


def _done(session, body, seconds: float) -> int:
    """A job of ``body`` stored as done after ``seconds`` [s] of running."""
    job = jobs.create_job(session, body, person="script")
    finished = T0 + datetime.timedelta(seconds=seconds)
    session.execute(update(Job).where(Job.id == job.id).values(state="done", started_at=T0, finished_at=finished))
    session.commit()
    return job.id


def test_a_kind_not_run_here_takes_its_typical_pace():
    paces = Paces()
    assert paces.of("viability") == job_kind("viability").typical_fraction
    assert paces.expected_seconds("mjtf", 270_000) == pytest.approx(OVERHEAD_S + job_kind("mjtf").typical_fraction * 2)


@pytest.mark.parametrize("pace", [0.05, 0.3, 7.0])
def test_the_pace_is_learned_from_the_kinds_done_jobs(session, pace):
    """Jobs that took ``pace`` of their worst case (a hidden truth varied here): the next is expected so."""
    for _ in range(3):
        _done(session, MJTFJobCreate(**LARGE), OVERHEAD_S + pace * LARGE_WORK / JOB_RATE_JUMPS_PER_S)
    learned = job_estimates.paces(session)
    assert learned.of("mjtf") == pytest.approx(pace, rel=1e-2) and learned.learned["mjtf"] == 3  # times to the µs
    assert learned.of("viability") == job_kind("viability").typical_fraction, "another kind: its own"
    queued = jobs.create_job(session, MJTFJobCreate(**SMALL), person="panel")
    expected = OVERHEAD_S + pace * WORK / JOB_RATE_JUMPS_PER_S
    assert queued.eta_s == pytest.approx(expected, rel=1e-2)
    assert queued.eta_max_s == pytest.approx(max(WORK / JOB_RATE_JUMPS_PER_S, queued.eta_s))


def test_the_median_of_the_newest_holds_against_one_odd_job(session):
    for seconds in (1.0, 1.0, 1.0, 30.0):  # one job waited on a cold worker
        _done(session, ViabilityJobCreate(kind="viability", states=8, actions=4), seconds)
    worst = 8**2 * 4**2
    assert job_estimates.paces(session).of("viability") == pytest.approx(
        (1.0 - OVERHEAD_S) * JOB_RATE_JUMPS_PER_S / worst
    )


def test_a_new_done_job_is_learned_at_once_and_unreadable_specs_are_skipped():
    started, finished = T0, T0 + datetime.timedelta(seconds=2.0)
    paces = learned_paces([("mjtf", {"version": 9, "kind": "mjtf"}, started, finished),
                           ("no-such-kind", {"kind": "no-such-kind"}, started, finished)])  # fmt: skip
    assert dict(paces.by_kind) == {}


def test_a_job_too_short_to_tell_its_pace_teaches_nothing(session):
    _done(session, ViabilityJobCreate(kind="viability", states=8, actions=4), 0.02)  # its overhead, nothing more
    assert job_estimates.paces(session).of("viability") == job_kind("viability").typical_fraction


def test_at_the_latest_is_never_sooner_than_expected(session):
    """A control study's jumps cost more than the map's: its expectation passes its bound at the
    worker's rate, and the bound says so rather than a time before the expected one."""
    from backend.jobs.control_study import ControlStudyJobCreate

    queued = jobs.create_job(session, ControlStudyJobCreate(kind="control-study", seeds=10, jumps=100), person="panel")
    assert job_kind("control-study").typical_fraction > 1 and queued.eta_max_s == pytest.approx(queued.eta_s)


def test_a_job_done_before_with_the_same_spec_is_expected_to_take_what_it_took(session):
    """An MFPT's chain comes from the cache the second time (0.05 s where the first took 11 s): a
    repeat is expected to take what the same job took last, whatever its kind's pace."""
    first = _done(session, MJTFJobCreate(**LARGE), 0.3)
    again = jobs.create_job(session, MJTFJobCreate(**LARGE), person="panel")
    other = jobs.create_job(session, MJTFJobCreate(**(LARGE | {"seed": 5})), person="panel")
    assert again.eta_s == pytest.approx(0.3, rel=1e-2), f"job {first} took 0.3 s"
    paces = job_estimates.paces(session)
    assert other.eta_s - again.eta_s == pytest.approx(paces.expected_seconds("mjtf", LARGE_WORK), rel=1e-2)
