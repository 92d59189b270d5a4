"""Where the service's compute runs: worker processes, never the service's own.

A simulation in the service's process holds its GIL and its request threads, so an API call, the
live view or the e-stop would wait behind it. Every kernel call the API or a job makes goes
instead to a :class:`ComputePool`: a small pool of worker processes (``spawn``: a fresh
interpreter, no inherited threads or locks) that load sim_core once and keep it. The service's
process only sends arguments and receives results. A pool runs whatever it is handed: the
functions, and the warm-up each worker runs first, come from the caller (``create_app``).

Three pools, so a long job never delays a quick call (:class:`Compute`): ``quick`` for the panel's
``/sim/*`` calls and ``POST /runs``, ``jobs`` for job chunks, and ``reads`` for the run list's
pages and exports (:mod:`backend.workers.store_reads`), which are not compute but held the
service's GIL as long. Work is bounded: a pool refuses a call when ``max_pending`` are already waiting
(:class:`ComputeBusy`, a 503 with Retry-After), and a call that outlives its ``timeout`` stops its
pool's workers, which start afresh for the next call (:class:`ComputeTimeout`). A worker that dies
(out of memory, a crash) is replaced the same way (:class:`ComputeFailed`). ``restart`` is also
how a job is cancelled mid-chunk.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import json
import logging
import multiprocessing
import os
import queue as queue_module
import signal
import threading
from collections.abc import Callable
from concurrent.futures.process import BrokenProcessPool

from backend.workers import progress as progress_module
from backend.workers.parent import watch_parent

log = logging.getLogger("parkourlab.compute")

QUICK_TIMEOUT = 60.0  # [s] the longest a quick call may take (they are bounded in size: milliseconds to seconds)
QUICK_PENDING = 64  # quick calls waiting at most; more get a 503
JOB_PENDING = 8  # job chunks in flight at most (the runner keeps the worker fed, no more)
WORKER_NICENESS = 10  # added to the workers' scheduling niceness (os.nice): compute yields to the service
READ_WORKERS = 2  # the reads pool's processes: on this 2-core machine a third gained nothing (docs/service.md)
# The readers answer requests, so they sit above compute; below the service's own process, so its
# event loop (the e-stop) still gets a core first when the readers fill both.
READ_NICENESS = 4
READ_PENDING = 256  # page reads waiting at most (one per client in flight: 50 clients need 50)


class ComputeBusy(RuntimeError):
    """The pool has ``max_pending`` calls waiting already: try again shortly."""


class ComputeTimeout(RuntimeError):
    """The call took longer than its limit; its pool's workers were stopped."""


class ComputeFailed(RuntimeError):
    """A worker process died during the call (or was stopped for another call); the pool starts afresh."""


def _init_worker(progress, niceness: int, service: int) -> None:
    # A Ctrl-C reaches the service's whole process group; the service stops its pools itself
    # (:func:`_stop`), and a worker that took it printed a KeyboardInterrupt traceback each.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    progress_module.attach(progress)
    # Below the service in the OS's eyes: with every core busy, the service's own process — HTTP,
    # the live view, the e-stop — still gets the CPU first.
    os.nice(niceness)
    watch_parent(service)  # the service's pid, from the service: it may be gone already (parent.py)


def as_json(function: Callable, *args) -> bytes:
    """In a worker: ``function(*args)`` encoded as JSON (NaN and infinities as null), so the
    service's process only forwards the bytes instead of encoding thousands of floats itself."""
    from experiments.manifest import json_safe

    return json.dumps(json_safe(function(*args)), allow_nan=False, separators=(",", ":")).encode()


def started() -> None:
    """A worker's first task when it is handed no warm-up: none; its process has started."""


class ComputePool:
    """``workers`` processes running one call each at a time; :meth:`run` from a thread,
    :meth:`call` from the event loop. Thread-safe; the executor is replaced only under its lock.

    ``warm_up`` (module-level, picklable, no arguments) is what :meth:`warm` runs in each worker:
    loading what a first call needs, off the request path."""

    def __init__(
        self,
        name: str,
        workers: int = 1,
        *,
        max_pending: int = QUICK_PENDING,
        niceness: int = WORKER_NICENESS,
        warm_up: Callable[[], None] = started,
    ):
        self.name = name
        self.workers = workers
        self.max_pending = max_pending
        self.niceness = niceness  # added to the workers' (os.nice)
        self.warm_up = warm_up  # what warm() runs in each worker
        self.restarts = 0  # times the workers were stopped and started afresh
        self._context = multiprocessing.get_context("spawn")
        self._lock = threading.Lock()  # guards _executor and _pending
        self._executor: concurrent.futures.ProcessPoolExecutor | None = None
        self._progress = None  # the current workers' progress queue (a new one with each start)
        self._pending = 0
        self._warm_ups: list[concurrent.futures.Future] = []  # the last warm()'s calls

    def submit(self, function: Callable, *args) -> concurrent.futures.Future:
        """``function(*args)`` in a worker; a ComputeBusy if ``max_pending`` calls are waiting."""
        with self._lock:
            if self._pending >= self.max_pending:
                raise ComputeBusy(f"{self._pending} {self.name} computations are waiting already; retry shortly")
            if self._executor is None:
                self._executor = self._start()
            try:
                future = self._executor.submit(function, *args)
            except BrokenProcessPool:  # a worker died since the last call: start afresh
                _stop(self._executor)
                self._executor = self._start()
                self.restarts += 1
                future = self._executor.submit(function, *args)
            self._pending += 1
        future.add_done_callback(self._finished)
        return future

    def run(self, function: Callable, *args, timeout: float | None = QUICK_TIMEOUT):
        """``function(*args)`` in a worker, waiting for it on this thread (no GIL held meanwhile)."""
        future = self.submit(function, *args)
        return self.result(future, timeout)

    async def call(self, function: Callable, *args, timeout: float = QUICK_TIMEOUT):
        """``function(*args)`` in a worker, awaited: no request thread is held while it computes."""
        future = self.submit(function, *args)
        try:
            return await asyncio.wait_for(asyncio.wrap_future(future), timeout)
        except TimeoutError:
            self.restart(f"a call took longer than {timeout:g} s")
            raise ComputeTimeout(f"the computation took longer than {timeout:g} s and was stopped") from None
        except BrokenProcessPool:
            self.restart("a worker died")
            raise ComputeFailed("the computation's worker process stopped; retry") from None

    def result(self, future: concurrent.futures.Future, timeout: float | None):
        """A submitted call's result, translating timeouts and dead workers."""
        try:
            return future.result(timeout)
        except concurrent.futures.TimeoutError:
            self.restart(f"a call took longer than {timeout:g} s")
            raise ComputeTimeout(f"the computation took longer than {timeout:g} s and was stopped") from None
        except BrokenProcessPool:
            self.restart("a worker died")
            raise ComputeFailed("the computation's worker process stopped; retry") from None

    def progress(self) -> list[tuple[int, int]]:
        """What the workers have reported (:func:`backend.workers.progress.report`) since the last
        look, oldest first."""
        with self._lock:
            queue = self._progress
        reports = []
        while queue is not None:
            try:
                reports.append(queue.get_nowait())
            except queue_module.Empty:
                break
        return reports

    def warm(self) -> list[concurrent.futures.Future]:
        """Start the workers now and run the warm-up in each (in the background); its calls."""
        self._warm_ups = [self.submit(self.warm_up) for _ in range(self.workers)]
        return list(self._warm_ups)

    @property
    def warming(self) -> bool:
        """Whether the warm-up :meth:`warm` started is still under way (a call now would wait for it)."""
        return any(not future.done() for future in self._warm_ups)

    def restart(self, why: str) -> None:
        """Stop the workers at once (their calls fail with ComputeFailed); the next call starts new ones."""
        with self._lock:
            executor, self._executor = self._executor, None
            if executor is not None:
                self.restarts += 1
        if executor is not None:
            log.info("%s compute pool restarted: %s", self.name, why)
            _stop(executor)

    def close(self) -> None:
        """Stop the workers (the service is stopping). A later call starts new ones, as after a
        restart: an app whose lifespan runs again (tests, schema fuzzing) keeps working."""
        with self._lock:
            executor, self._executor = self._executor, None
        if executor is not None:
            _stop(executor)

    def _start(self) -> concurrent.futures.ProcessPoolExecutor:
        # A fresh progress queue with each start: a worker stopped mid-put may leave the old one locked.
        self._progress = self._context.Queue()
        initargs = (self._progress, self.niceness, os.getpid())
        return concurrent.futures.ProcessPoolExecutor(
            self.workers, mp_context=self._context, initializer=_init_worker, initargs=initargs
        )

    def _finished(self, _future) -> None:
        with self._lock:
            self._pending -= 1


def _stop(executor: concurrent.futures.ProcessPoolExecutor) -> None:
    """Terminate the executor's processes and let it go (no waiting for calls under way)."""
    processes = list((executor._processes or {}).values())  # the only handle on them: it offers no kill
    for process in processes:
        process.terminate()
    executor.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.join(5)


class Compute:
    """The service's pools: ``quick`` for API calls, ``jobs`` for job chunks, ``reads`` for the
    run list's pages and exports. ``warm_up`` is what the quick and job workers run first (the
    kernels; ``jobs_warm_up``, where given, the job worker's: every job kind's), ``reads_warm_up``
    what the read workers do (the store and the schemas); without them :meth:`warm` only starts
    the workers."""

    def __init__(
        self,
        quick: ComputePool | None = None,
        jobs: ComputePool | None = None,
        *,
        warm_up: Callable[[], None] = started,
        reads_warm_up: Callable[[], None] = started,
        jobs_warm_up: Callable[[], None] | None = None,
    ):
        self.quick = quick or ComputePool("quick", max_pending=QUICK_PENDING, warm_up=warm_up)
        self.jobs = jobs or ComputePool("jobs", max_pending=JOB_PENDING, warm_up=jobs_warm_up or warm_up)
        self.reads = ComputePool(
            "reads", READ_WORKERS, max_pending=READ_PENDING, niceness=READ_NICENESS, warm_up=reads_warm_up
        )

    def warm(self) -> None:
        """Warm the pools: the reads and quick ones now, the job worker once the quick one is warm.
        Loading every job kind's kernels beside them took the cores the requests' pools load on:
        health was ok 9.8-14.6 s after the start, 5.5-11.3 s with the job worker after (3 starts
        each, alternated, on the loaded 2-core machine)."""
        self.reads.warm()
        warm_ups = self.quick.warm()
        lock = threading.Lock()

        def one_done(future) -> None:
            with lock:
                warm_ups.remove(future)
                if warm_ups:
                    return
            self.jobs.warm()

        for future in list(warm_ups):
            future.add_done_callback(one_done)

    def warming(self) -> list[str]:
        """The pools whose warm-up is under way, by name (``reads``, ``quick``, ``jobs``)."""
        return [pool.name for pool in (self.reads, self.quick, self.jobs) if pool.warming]

    def ready(self) -> bool:
        """Whether requests wait for no warm-up: the reads and quick pools are warm (a job waits
        in the queue anyway, and the job worker's warm-up — every job kind's kernels — may take
        minutes on a fresh numba cache)."""
        return not (self.reads.warming or self.quick.warming)

    def close(self) -> None:
        self.quick.close()
        self.jobs.close()
        self.reads.close()
