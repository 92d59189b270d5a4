"""The parent watch (backend/workers/parent.py): a worker ends once the service that started it is gone."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from backend.workers.parent import PARENT_CHECK_S


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
from backend.workers.pools import ComputePool
pool = ComputePool("orphaned")
print(pool.run(os.getpid, timeout=60), flush=True)
time.sleep(600)
"""


def test_a_worker_that_starts_after_its_service_is_gone_ends_at_once():
    """Issue 40: a worker spawned as the service ended was re-parented before it looked, took its
    new parent for the service, and waited for ever. The service's pid comes from the service."""
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()  # a process id that is no one's parent now
    worker = subprocess.Popen(
        [sys.executable, "-c", LATE_WORKER.format(parent=gone.pid)], cwd=Path(__file__).parents[3]
    )
    try:
        assert worker.wait(10 * PARENT_CHECK_S + 10) == 0, "it ended by itself"
    except subprocess.TimeoutExpired:
        worker.kill()
        worker.wait()
        pytest.fail("a worker whose service was gone as it started did not end")


LATE_WORKER = """
import time
from backend.workers.parent import watch_parent
watch_parent({parent})
time.sleep(600)
"""
