"""The compute worker pools: calls run in other processes, are bounded in number and time, and a
dead or stopped worker is replaced."""

import asyncio
import functools
import os
import signal
import time

import pytest

from backend.workers.pools import (
    READ_NICENESS,
    WORKER_NICENESS,
    Compute,
    ComputeBusy,
    ComputeFailed,
    ComputePool,
    ComputeTimeout,
)
from sim_core.model.errors import ParameterError

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


def _ignores_ctrl_c() -> bool:
    return signal.getsignal(signal.SIGINT) is signal.SIG_IGN


def test_a_worker_leaves_a_ctrl_c_to_the_service():
    """Ctrl-C reaches the service's process group: the workers printed a KeyboardInterrupt traceback
    each; the service ends them itself."""
    pool = ComputePool("ctrl-c")
    try:
        assert pool.run(_ignores_ctrl_c, timeout=WAIT_S)
    finally:
        pool.close()


_warmed = False  # in a worker: whether its warm-up ran


def _warm_up() -> None:
    global _warmed
    _warmed = True


def _was_warmed() -> bool:
    return _warmed


def test_a_pool_runs_the_warm_up_it_was_handed_first():
    warmed, plain = ComputePool("warmed", warm_up=_warm_up), ComputePool("plain")
    try:
        warmed.warm()  # one worker: the warm-up is its first task, the call its second
        assert warmed.run(_was_warmed, timeout=WAIT_S) is True
        plain.warm()
        assert plain.run(_was_warmed, timeout=WAIT_S) is False, "without a warm-up, warm() only starts the workers"
    finally:
        warmed.close()
        plain.close()


def test_the_service_pools_take_the_warm_ups_they_are_handed():
    compute = Compute(warm_up=_warm_up, reads_warm_up=_was_warmed)  # no process starts until a call
    assert compute.quick.warm_up is compute.jobs.warm_up is _warm_up and compute.reads.warm_up is _was_warmed
    assert (compute.quick.workers, compute.jobs.workers, compute.reads.workers) == (1, 1, 2)


def test_a_pool_is_warming_until_its_warm_up_has_run():
    pool = ComputePool("warming", warm_up=functools.partial(_sleep, 0.5))
    try:
        assert not pool.warming, "never warmed: nothing to wait for"
        pool.warm()
        assert pool.warming, "a worker's start alone takes longer than this look"
        pool.run(_pid, timeout=WAIT_S)  # one worker: the call runs after the warm-up
        assert not pool.warming
    finally:
        pool.close()


def test_the_service_is_ready_once_its_request_pools_are_warm_and_the_job_worker_warms_after():
    """The job worker's warm-up (every job kind's kernels) starts once the quick pool is warm: at
    the same time, it took the cores the requests' pools load on."""
    compute = Compute(warm_up=functools.partial(_sleep, 0.5), reads_warm_up=_warm_up, jobs_warm_up=_warm_up)
    try:
        assert compute.ready() and compute.warming() == []
        compute.warm()
        assert not compute.ready() and "quick" in compute.warming() and "jobs" not in compute.warming()
        compute.quick.run(_pid, timeout=WAIT_S)
        compute.reads.run(_pid, timeout=WAIT_S)
        compute.reads.run(_pid, timeout=WAIT_S)
        deadline = time.monotonic() + WAIT_S
        while not compute.ready() or compute.warming():  # the reads' second worker; the job worker's turn
            assert time.monotonic() < deadline, compute.warming()
            time.sleep(0.05)
        assert compute.jobs.run(_was_warmed, timeout=WAIT_S) is True, "the job worker was warmed"
    finally:
        compute.close()
