"""The job runner: one background thread that takes the stored jobs to their end, one at a time.

An MJTF job survives crashes trial by trial. The runner takes the study's one plan from sim_core
— the levels' starts (:func:`sim_core.robustness.mjtf.level_starts`, in the job worker), then the trials in
chunks (:func:`sim_core.robustness.mjtf_plan.plan_trials`) leaving out the trials already stored — runs the
chunks in the service's job worker process (:mod:`backend.workers.pools`; never in the service's
own, where they would hold up the API) or on the Dask cluster named by ``PARKOUR_DASK_ADDRESS``,
and commits each chunk's trials and the progress in one transaction as it finishes. Killed
mid-job, the service finds the job at the next start, recomputes only the missing trials — their
seeds depend on ``(seed, level, index)`` alone — and ends with exactly the trials asked for, none
lost and none duplicated (the unique key refuses a second copy). Sweeps, basins and gait searches
are deterministic: they run whole through the chunk map, report progress per chunk, and store
their result on the job when done; a restart recomputes them. Cancelling marks the job; the runner
sees it within ``CANCEL_POLL`` and stops the worker at once (a chunk under way is dropped: its
trials are not committed, and nothing else depends on it). A service stopping is seen as soon: the
job stays running, for the next start to resume, and no queued job starts. On a full disk a job
pauses: what it computed waits in memory and is committed when there is room again
(:mod:`backend.services.storage_waits`);
stopped meanwhile, it stays running and the next start resumes it. The jobs a crash left unfinished
are settled on the runner's thread too, so a full disk never holds up the service's start.
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
from backend.jobs.mjtf import MJTFSpec
from backend.repositories import jobs as stored_jobs
from backend.schemas.jobs import JobState
from backend.services.storage_waits import Stopped, Waiting, when_room
from backend.services.studies import run_study, run_study_here
from backend.store.database import StorageFull
from backend.store.models import Trial, utcnow
from backend.workers.pools import ComputePool
from experiments.cluster import as_completed_results, chunk_map_for, dask_client
from experiments.manifest import json_safe
from sim_core.chunks import Cancelled
from sim_core.model.failures import OK, Failure
from sim_core.robustness.mjtf_plan import TrialChunk, plan_trials

log = logging.getLogger("parkourlab.jobs")
T = TypeVar("T")

CHUNK_TRIALS = 32  # tens of trials per commit: a 3 ms trial alone would drown in overhead
CANCEL_POLL = 0.2  # [s] how often the runner looks for a cancel while a worker computes
IN_FLIGHT = 4  # chunks handed to the worker ahead of the one awaited: it never idles between chunks


class JobRunner:
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
        if job_kind(kind).run is None:  # MJTF: trials stored chunk by chunk, a restart resumes them
            self._run_mjtf(job_id, spec)
        else:
            self._run_study(job_id, spec)

    def _run_mjtf(self, job_id: int, spec: MJTFSpec) -> None:
        """The study's trials not stored yet, chunk by chunk as sim_core plans them."""
        from sim_core.robustness.mjtf import level_starts  # the kernels load with the first job (simulation.py)
        from sim_core.robustness.mjtf_trials import run_trials

        model, noise = spec.model.params(), spec.noise.model()
        guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
        try:
            starts = self.pool.submit(functools.partial(level_starts, guess=guess), model, np.radians(spec.psi0_deg),
                                      spec.zeta0s)  # fmt: skip
            levels = self._await(job_id, starts)
        except Cancelled:
            self._cancelled(job_id)  # marks it cancelled
            return
        with self.sessions() as session:
            stored = stored_jobs.stored_indices(session, job_id)
        done = [stored.get(level, set()) for level in range(len(levels))]
        chunks = plan_trials(len(levels), spec.trials, spec.seed, self.chunk_trials, done)
        if self._cancelled(job_id):
            return
        arguments = [chunk.arguments(model, levels, noise, spec.cap) for chunk in chunks]
        results = self._execute(job_id, run_trials, arguments)
        try:
            for index, (jumps, status) in results:
                chunk = chunks[index]
                zeta0 = levels[chunk.level].zeta0
                self._stored(f"storing job {job_id}'s trials", self._commit_chunk, job_id, chunk, zeta0, jumps, status)
                if self._cancelled(job_id):
                    return
        except Cancelled:
            self._cancelled(job_id)  # marks it cancelled
            return
        finally:
            results.close()  # on a Dask cluster, cancels the chunks not yet finished
        with self.sessions() as session:
            job = stored_jobs.get(session, job_id)
            job.state, job.finished_at = JobState.DONE, utcnow()
            session.commit()

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

    def _commit_chunk(self, job_id: int, chunk: TrialChunk, zeta0: float, jumps, status) -> None:
        with self.sessions() as session:
            stored_jobs.add_trials(
                session,
                job_id,
                (
                    Trial(
                        job_id=job_id,
                        level=chunk.level,
                        index=int(i),
                        zeta0=float(zeta0),
                        seed=int(seed),
                        jumps=int(n),
                        failure_code=None if code == OK else Failure(int(code)).code,
                    )
                    for i, seed, n, code in zip(chunk.indices, chunk.seeds, jumps, status, strict=True)
                ),
            )
            session.commit()
