"""The compute worker pools: calls run in other processes, are bounded in number and time, and a
dead or stopped worker is replaced."""

import asyncio
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from backend.services.compute import (
    PARENT_CHECK_S,
    READ_NICENESS,
    WORKER_NICENESS,
    ComputeBusy,
    ComputeFailed,
    ComputePool,
    ComputeTimeout,
    report,
)
from sim_core.errors import ParameterError

WAIT_S = 60.0  # [s] a worker's start and a call, generously


def _pid() -> int:
    return os.getpid()


def _sleep(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


def _niceness() -> int:
    return os.nice(0)


def _die() -> None:
    os._exit(3)


def _refuse() -> None:
    raise ParameterError("zeta0", "must be in (0, 1), got 1.2")


def _count_to(total: int) -> int:
    for done in range(1, total + 1):
        report(done, total)
    return total


@pytest.fixture
def pool():
    pool = ComputePool("test", max_pending=2)
    yield pool
    pool.close()


def test_calls_run_in_a_worker_process_and_errors_come_back_as_raised(pool):
    assert pool.run(_pid, timeout=WAIT_S) != os.getpid()
    with pytest.raises(ParameterError) as error:
        pool.run(_refuse, timeout=WAIT_S)
    assert error.value.field == "zeta0", "a user's error keeps its field across the process boundary"
    assert asyncio.run(pool.call(_sleep, 0.0, timeout=WAIT_S)) == 0.0


def test_calls_beyond_the_pending_bound_are_refused(pool):
    pool.run(_pid, timeout=WAIT_S)  # started
    first, second = pool.submit(_sleep, 0.5), pool.submit(_sleep, 0.5)
    with pytest.raises(ComputeBusy, match="2 test computations are waiting"):
        pool.submit(_sleep, 0.0)
    assert pool.result(first, WAIT_S) == pool.result(second, WAIT_S) == 0.5
    assert pool.run(_sleep, 0.0, timeout=WAIT_S) == 0.0, "room again once they finished"


def test_a_call_past_its_time_stops_the_workers_and_the_next_starts_afresh(pool):
    before = pool.run(_pid, timeout=WAIT_S)
    with pytest.raises(ComputeTimeout, match=r"longer than 0\.5 s"):
        pool.run(_sleep, 30.0, timeout=0.5)
    assert pool.restarts == 1 and pool.run(_pid, timeout=WAIT_S) != before


def test_a_dead_worker_is_replaced(pool):
    with pytest.raises(ComputeFailed):
        pool.run(_die, timeout=WAIT_S)
    assert pool.run(_sleep, 0.0, timeout=WAIT_S) == 0.0


def test_workers_report_progress(pool):
    assert pool.run(_count_to, 3, timeout=WAIT_S) == 3
    deadline = time.monotonic() + WAIT_S
    reports = []
    while len(reports) < 3 and time.monotonic() < deadline:
        reports += pool.progress()
    assert reports == [(1, 3), (2, 3), (3, 3)]


def test_a_closed_pool_starts_afresh_when_called_again(pool):
    before = pool.run(_pid, timeout=WAIT_S)
    pool.close()
    assert pool.run(_pid, timeout=WAIT_S) != before


def test_a_pool_sets_its_workers_niceness():
    compute, reads = ComputePool("niced"), ComputePool("readers", niceness=READ_NICENESS)
    try:
        assert compute.run(_niceness, timeout=WAIT_S) == os.nice(0) + WORKER_NICENESS
        assert reads.run(_niceness, timeout=WAIT_S) == os.nice(0) + READ_NICENESS < os.nice(0) + WORKER_NICENESS
    finally:
        compute.close()
        reads.close()


def _gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (a zombie its new parent has not reaped yet counts)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0] == "Z"
    except FileNotFoundError:
        return True


def test_workers_end_when_the_service_is_killed_outright():
    owner = subprocess.Popen(
        [sys.executable, "-c", ORPHANING_SERVICE], stdout=subprocess.PIPE, text=True, cwd=Path(__file__).parents[3]
    )
    try:
        worker = int(owner.stdout.readline())
        assert not _gone(worker)
    finally:
        owner.kill()
        owner.wait()
    deadline = time.monotonic() + 10 * PARENT_CHECK_S
    while not _gone(worker):
        if time.monotonic() > deadline:
            os.kill(worker, signal.SIGKILL)
            pytest.fail("a worker outlived its killed service")
        time.sleep(0.1)


# A service in miniature: a pool with a worker started, then killed with SIGKILL by the test.
ORPHANING_SERVICE = """
import os, time
from backend.services.compute import ComputePool
pool = ComputePool("orphaned")
print(pool.run(os.getpid, timeout=60), flush=True)
time.sleep(600)
"""
