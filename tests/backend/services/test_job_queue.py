"""The job queue (backend/services/job_queue.py): a budget of queued work, each client's share of
it, and where each job stands. The budgets are made small here; the jobs stay queued (no runner)."""

from __future__ import annotations

import pytest
from sqlalchemy import update

from backend.errors import QueueFull
from backend.jobs import job_kind, worst_case_jumps
from backend.jobs.mjtf import MJTFJobCreate
from backend.schemas.job_budget import JOB_RATE_JUMPS_PER_S
from backend.services import job_queue, jobs
from backend.services.job_estimates import OVERHEAD_S
from backend.store.models import Job
from tests.backend.services.jobs_helpers import SMALL

WORK = worst_case_jumps(MJTFJobCreate(**SMALL))[0]  # 2 levels x 10 trials x 200 jumps = 4000
MJTF_PACE = job_kind("mjtf").typical_fraction


@pytest.fixture
def budget(monkeypatch):
    """A queue of room for ten SMALL jobs, at most six of them one client's."""
    monkeypatch.setattr(job_queue, "QUEUE_BUDGET_JUMPS", 10 * WORK)
    monkeypatch.setattr(job_queue, "PERSON_SHARE", 0.6)


def _submit(session, client: str, **changes):
    return jobs.create_job(session, MJTFJobCreate(**(SMALL | changes)), person=client)


def test_queued_jobs_stand_in_line_oldest_first_with_estimates(session, budget):
    submitted = [_submit(session, "script") for _ in range(3)]
    assert [job.queue_position for job in submitted] == [1, 2, 3]
    assert [job.submitted_by for job in submitted] == ["script"] * 3
    now = [jobs.get_job(session, job.id) for job in submitted]
    expected = OVERHEAD_S + MJTF_PACE * WORK / JOB_RATE_JUMPS_PER_S  # no job done here yet: the kind's typical pace
    latest = max(WORK / JOB_RATE_JUMPS_PER_S, expected)  # never sooner than expected (a job's overhead)
    assert [job.eta_s for job in now] == pytest.approx([k * expected for k in (1, 2, 3)])
    assert [job.eta_max_s for job in now] == pytest.approx([k * latest for k in (1, 2, 3)])


def test_a_running_job_counts_what_it_has_left_and_moves_the_line_up(session, budget):
    first, second = _submit(session, "script"), _submit(session, "script")
    session.execute(update(Job).where(Job.id == first.id).values(state="running", completed=first.total // 2))
    session.commit()
    running, waiting = jobs.get_job(session, first.id), jobs.get_job(session, second.id)
    expected = OVERHEAD_S + MJTF_PACE * WORK / JOB_RATE_JUMPS_PER_S
    latest = max(WORK / JOB_RATE_JUMPS_PER_S, expected)
    assert running.queue_position is None and waiting.queue_position == 1
    assert (running.eta_s, waiting.eta_s) == pytest.approx((expected / 2, 1.5 * expected)), "half of it left"
    assert (running.eta_max_s, waiting.eta_max_s) == pytest.approx((latest / 2, 1.5 * latest))
    page = jobs.list_jobs(session, state=None, limit=10, cursor=None)
    assert {job.id: job.queue_position for job in page.items} == {first.id: None, second.id: 1}


def test_an_ended_job_has_no_place_and_takes_no_room(session, budget):
    done = _submit(session, "script")
    session.execute(update(Job).where(Job.id == done.id).values(state="done", completed=done.total))
    session.commit()
    ended = jobs.get_job(session, done.id)
    assert ended.queue_position is None and ended.eta_s is None and ended.eta_max_s is None
    assert [_submit(session, "script").queue_position for _ in range(6)] == [1, 2, 3, 4, 5, 6], "the done job is free"


def test_one_client_cannot_take_the_whole_queue(session, budget):
    for _ in range(6):
        _submit(session, "batch-script")
    with pytest.raises(QueueFull) as refused:
        _submit(session, "batch-script")
    message = str(refused.value)
    assert message.startswith("batch-script already holds 2.4e+04 jumps of queued work") and "share" in message
    assert _submit(session, "panel").queue_position == 7, "another client still finds room"


def test_past_the_budget_every_client_is_refused_with_what_is_queued(session, budget):
    for client in ("a", "b", "c", "d", "e"):
        _submit(session, client)
        _submit(session, client)
    with pytest.raises(QueueFull) as refused:
        _submit(session, "f")
    message = str(refused.value)
    assert "the job queue is full" in message and "10 jobs unfinished, 4e+04 jumps of work" in message
    assert jobs.list_jobs(session, state=None, limit=50, cursor=None).total == 10, "nothing stored for the refusal"


def test_a_cancelled_job_gives_its_room_back(session, budget):
    queued = [_submit(session, "script") for _ in range(6)]
    jobs.cancel_job(session, queued[0].id)
    assert _submit(session, "script").queue_position == 6


def test_one_person_cannot_fill_the_waiting_line_with_small_jobs(session, budget, monkeypatch):
    """Issue 40: 1,047 one-jump jobs from one client made every other client's job a 429."""
    monkeypatch.setattr(job_queue, "QUEUE_BUDGET_JUMPS", 100 * WORK)
    monkeypatch.setattr(job_queue, "PERSON_QUEUED_JOBS", 3)
    for _ in range(3):
        _submit(session, "alice")
    with pytest.raises(QueueFull) as refused:
        _submit(session, "alice")
    assert str(refused.value).startswith("alice has 3 jobs waiting, the most one person may")
    assert _submit(session, "bob").queue_position == 4, "another person still finds room"
