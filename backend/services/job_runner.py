"""The job runner: one background thread that takes the stored jobs to their end, one at a time.

Its work runs in the service's job worker process (:mod:`backend.workers.pools`; never in the
service's own, where it would hold up the API) or on the Dask cluster named by
``PARKOUR_DASK_ADDRESS``. Three ways, by kind (:mod:`backend.jobs`):

- MJTF survives crashes trial by trial: sim_core's one plan of the study (the levels' starts, then
  the trials in chunks, :func:`sim_core.robustness.mjtf_plan.plan_trials`) less the trials stored;
  each chunk's trials and the progress committed in one transaction. Their seeds depend on
  ``(seed, level, index)`` alone, so a restart after kill -9 ends with exactly the trials asked for
  (the unique key refuses a second copy).
- A chunked kind (a foothold study, trials in a world: :class:`backend.jobs.base.Chunked`) stores
  each chunk's JSON result as it finishes; a restart computes the chunks missing, and the result is
  made from all of them as stored — the uninterrupted job's.
- The other kinds are deterministic: run whole through the chunk map, progress per chunk, the
  result stored when done; a restart recomputes them.

Cancelling marks the job; the runner sees it within ``CANCEL_POLL`` and stops the worker at once
(a chunk under way is dropped). A service stopping is seen as soon: the job stays running, for the
next start to resume, and no queued job starts. On a full disk a job pauses, what it computed
waiting in memory (:mod:`backend.services.storage_waits`). The jobs a crash left unfinished are
settled on the runner's thread too, so a full disk never holds up the service's start.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import functools
import logging
import queue
import threading
from collections.abc import Callable, Iterator
from typing import TypeVar

import numpy as np
from sqlalchemy.orm import Session, sessionmaker

from backend.jobs import decode, job_kind
from backend.repositories import jobs as stored_jobs
from backend.schemas.jobs import JobState
from backend.services.job_runs import RunsByKind
from backend.services.storage_waits import Stopped, Waiting, when_room
from backend.services.studies import run_study, run_study_here
from backend.store.database import StorageFull
from backend.store.models import utcnow
from backend.workers.pools import ComputePool
from experiments.cluster import as_completed_results, chunk_map_for, dask_client
from experiments.manifest import json_safe
from sim_core.chunks import Cancelled

log = logging.getLogger("parkourlab.jobs")
T = TypeVar("T")

CHUNK_TRIALS = 32  # tens of trials per commit: a 3 ms trial alone would drown in overhead
CANCEL_POLL = 0.2  # [s] how often the runner looks for a cancel while a worker computes
IN_FLIGHT = 4  # chunks handed to the worker ahead of the one awaited: it never idles between chunks


class JobRunner(RunsByKind):
    """Runs jobs one at a time on a background thread, resuming unfinished ones at start."""

    def __init__(
        self,
        sessions: sessionmaker[Session],
        pool: ComputePool,
        *,
        chunk_trials: int = CHUNK_TRIALS,
        dask_address: str | None = None,
        waiting: Waiting | None = None,
    ):
        self.sessions = sessions
        self.pool = pool  # the job worker: chunks run there, not in this process
        self.chunk_trials = chunk_trials
        self.dask_address = dask_address
        self.queue: queue.Queue[int | None] = queue.Queue()
        self.thread: threading.Thread | None = None
        self._stopping = threading.Event()  # set by stop(): a job paused on a full disk gives up its wait
        self.waiting = waiting  # the writes waiting for disk space, which the health check lists

    def start(self) -> None:
        """Start the runner's thread. Jobs a crash left running or cancelling are settled there,
        not here: on a full disk that write waits for space, and start-up (reads, DELETE: the way to
        free space) must not wait with it."""
        self.thread = threading.Thread(target=self._loop, name="parkourlab-jobs", daemon=True)
        self.thread.start()

    def submit(self, job_id: int) -> None:
        self.queue.put(job_id)

    def stop(self, timeout: float = 10.0) -> None:
        self._stopping.set()
        if self.thread is not None:
            self.queue.put(None)
            self.thread.join(timeout)

    def _loop(self) -> None:
        try:
            unfinished = self._stored("settling the jobs left unfinished at the last stop", self._recover)
        except Stopped:
            return
        for job_id in unfinished:
            self.queue.put(job_id)
        # Stopping, the queued jobs stay queued: a job started now would start a job worker that
        # the service, ending, might no longer stop.
        while (job_id := self.queue.get()) is not None and not self._stopping.is_set():
            try:
                self.run(job_id)
            except Stopped:  # stopped mid-job (or paused on a full disk): still running, the next start resumes it
                return
            except Exception as error:  # a job's failure is recorded; the runner goes on
                log.exception("job %s failed", job_id)
                with self.sessions() as session:
                    job = stored_jobs.find(session, job_id)
                    if job is not None:
                        job.state, job.error, job.finished_at = (
                            JobState.FAILED,
                            f"{type(error).__name__}: {error}",
                            utcnow(),
                        )
                        session.commit()

    def _recover(self) -> list[int]:
        """Jobs left running are queued again (they resume from their stored trials), those left
        cancelling are cancelled; the queued jobs' ids, oldest first."""
        with self.sessions() as session:
            stored_jobs.recover_interrupted(session)
            session.commit()
            return stored_jobs.queued_ids(session)

    def run(self, job_id: int) -> None:
        """Run (or resume) one job to its end, committing every chunk."""
        with self.sessions() as session:
            # Claimed with one conditional UPDATE, as cancel_job changes state: a cancel that lands
            # between reading the job and writing "running" is not overwritten.
            claimed = stored_jobs.claim(session, job_id)
            session.commit()
            if not claimed:
                return
            job = stored_jobs.get(session, job_id)
            kind, spec = job.kind, decode(job.spec)
        if job_kind(kind).chunked is not None:  # chunks stored as they finish, a restart computes the rest
            self._run_chunked(job_id, spec)
        elif job_kind(kind).run is None:  # MJTF: trials stored chunk by chunk, a restart resumes them
            self._run_mjtf(job_id, spec)
        else:
            self._run_study(job_id, spec)

    def _run_study(self, job_id: int, spec) -> None:
        """Sweeps, basins and gait searches: computed whole (a restart recomputes them — they are
        deterministic), chunked through the chunk map, progress per chunk, result stored at the end."""

        def progress(done: int, total: int) -> None:
            with self.sessions() as session:
                job = stored_jobs.get(session, job_id)
                if job.state == JobState.CANCELLING:
                    raise Cancelled
                job.completed, job.total = done, total
                with contextlib.suppress(StorageFull):  # progress can wait for space; the result cannot
                    session.commit()

        try:
            if self.dask_address is None:
                result = self._await(job_id, self.pool.submit(run_study_here, spec), progress)
            else:
                with chunk_map_for(self.dask_address) as chunk_map:
                    result = run_study(spec, chunk_map, progress)
        except Cancelled:
            with self.sessions() as session:
                job = stored_jobs.get(session, job_id)
                job.state, job.finished_at = JobState.CANCELLED, utcnow()
                session.commit()
            return
        self._stored(f"storing job {job_id}'s result", self._store_result, job_id, json_safe(result))

    def _store_result(self, job_id: int, result: dict) -> None:
        with self.sessions() as session:
            job = stored_jobs.get(session, job_id)
            job.result = result
            job.completed = job.total
            job.state, job.finished_at = JobState.DONE, utcnow()
            session.commit()

    def _stored(self, what: str, write: Callable[..., T], *args) -> T:
        """``write(*args)`` (one transaction), again every few seconds while the disk is full: the
        job pauses with what it computed in memory, and goes on when space returns."""
        engine = self.sessions.kw["bind"]
        return when_room(
            functools.partial(write, *args), what=what, engine=engine, stopping=self._stopping, waiting=self.waiting
        )

    def _execute(
        self, job_id: int, function: Callable, arguments: list[tuple]
    ) -> Iterator[tuple[int, tuple[np.ndarray, np.ndarray]]]:
        """``(chunk index, function(*arguments[index]))`` as chunks finish: from the job worker in
        order, a few handed to it ahead, or from the Dask cluster. Raises Cancelled (the worker
        stopped) on a cancel."""
        if self.dask_address is not None:
            with dask_client(self.dask_address) as client:
                yield from as_completed_results(client, function, arguments)
            return
        in_flight: dict[int, concurrent.futures.Future] = {}
        for index in range(len(arguments)):
            for ahead in range(index, min(index + IN_FLIGHT, len(arguments))):
                if ahead not in in_flight:
                    in_flight[ahead] = self.pool.submit(function, *arguments[ahead])
            yield index, self._await(job_id, in_flight.pop(index))

    def _await(self, job_id: int, future: concurrent.futures.Future, progress: Callable | None = None):
        """The worker's result, looking every CANCEL_POLL for a cancel (then the worker is stopped
        and Cancelled raised) or the service stopping (Stopped), and passing on the progress it reports."""
        while True:
            try:
                return future.result(CANCEL_POLL)
            except concurrent.futures.TimeoutError:
                pass
            finally:
                for done, total in self.pool.progress() if progress is not None else ():
                    progress(done, total)
            if self._stopping.is_set():
                # The service is stopping: the job stays running, and the next start resumes it.
                # Waiting on would hold the shutdown up to stop()'s timeout, and the worker's end
                # (the service stops its pools next) would fail the job as a dead worker.
                raise Stopped
            if self._cancel_requested(job_id):
                self.pool.restart(f"job {job_id} was cancelled")
                raise Cancelled

    def _cancel_requested(self, job_id: int) -> bool:
        with self.sessions() as session:
            return stored_jobs.state_of(session, job_id) == JobState.CANCELLING

    def _cancelled(self, job_id: int) -> bool:
        """Whether the job is to stop: a cancel asked for is marked done (cancelled) here."""
        with self.sessions() as session:
            job = stored_jobs.get(session, job_id)
            if job.state == JobState.CANCELLING:
                job.state, job.finished_at = JobState.CANCELLED, utcnow()
                session.commit()
                return True
            return job.state != JobState.RUNNING
