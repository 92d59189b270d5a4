"""Progress from a worker (backend/workers/progress.py): reported there, read by the pool in order;
outside a worker, reporting does nothing."""

import queue
import time

import pytest

from backend.workers import progress
from backend.workers.pools import ComputePool
from backend.workers.progress import report

WAIT_S = 60.0  # [s] a worker's start and a call, generously


def _count_to(total: int) -> int:
    for done in range(1, total + 1):
        report(done, total)
    return total


@pytest.fixture
def pool():
    pool = ComputePool("test", max_pending=2)
    yield pool
    pool.close()


def test_workers_report_progress(pool):
    assert pool.run(_count_to, 3, timeout=WAIT_S) == 3
    deadline = time.monotonic() + WAIT_S
    reports = []
    while len(reports) < 3 and time.monotonic() < deadline:
        reports += pool.progress()
    assert reports == [(1, 3), (2, 3), (3, 3)]


def test_report_puts_on_the_attached_queue_and_nowhere_without_one(monkeypatch):
    monkeypatch.setattr(progress, "_queue", None)  # restored afterwards
    report(1, 2)  # outside a worker: no queue, nothing happens (and no error)
    attached = queue.SimpleQueue()
    progress.attach(attached)
    report(1, 2)
    assert attached.get_nowait() == (1, 2) and attached.empty()
