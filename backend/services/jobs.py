"""Batch jobs: MJTF studies, energy sweeps, basins and gait searches that live in the database.

A job is a row. An MJTF job survives crashes trial by trial: its trials are rows with the
idempotent key ``(job, level, index)``. The runner (one background thread) works through a
job in chunks of trials: it computes the trials still missing, runs the chunks — in the
service's job worker process (:mod:`backend.workers.pools`; never in the service's own, where
they would hold up the API), or on the Dask cluster named by ``PARKOUR_DASK_ADDRESS`` — and
commits each chunk's trials and the progress in one transaction as it finishes. Killed mid-job, the service finds
the job at the next start, recomputes only the missing trials — their seeds depend on
``(seed, level, index)`` alone — and ends with exactly the trials asked for, none lost and none
duplicated (the unique key refuses a second copy). Sweeps, basins and gait searches are
deterministic: they run whole through the chunk map, report progress per chunk, and store
their result on the job when done; a restart recomputes them. Cancelling marks the job; the
runner sees it within ``CANCEL_POLL`` and stops the worker at once (a chunk under way is dropped:
its trials are not committed, and nothing else depends on it). On a full disk a job pauses: what
it computed waits in memory and is committed when there is room again (tried every
``STORAGE_RETRY``); stopped meanwhile, it stays running and the next start resumes it.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import functools
import logging
import math
import queue
import threading
from collections.abc import Callable, Iterator
from dataclasses import asdict

import numpy as np
from sqlalchemy import func, select, update
from sqlalchemy.orm import Session, sessionmaker

from backend.services.job_specs import decode, encode, spec_of
from backend.services.records import fetch, locked, newest_first, page
from backend.services.simulation import current_code_version, model_params, run_study, run_study_here
from backend.store.database import StorageFull, after_storage_full
from backend.store.models import Experiment, Job, Trial, utcnow
from backend.workers.pools import ComputePool
from experiments.cluster import as_completed_results, chunk_map_for, dask_client
from experiments.manifest import json_safe
from sim_core.chunks import Cancelled
from sim_core.failures import OK, Failure
from sim_core.noise import NoiseModel, trial_seeds

log = logging.getLogger("parkourlab.jobs")

CHUNK_TRIALS = 32  # tens of trials per commit: a 3 ms trial alone would drown in overhead
STORAGE_RETRY = 5.0  # [s] between tries to store a paused job's results on a full disk
CANCEL_POLL = 0.2  # [s] how often the runner looks for a cancel while a worker computes
IN_FLIGHT = 4  # chunks handed to the worker ahead of the one awaited: it never idles between chunks
ACTIVE = ("queued", "running", "cancelling")
FINAL = ("done", "cancelled", "failed")


def create_job(session: Session, body) -> Job:
    """Store a job (any of ``schemas.JOB_KINDS``); MJTF totals count trials, other kinds chunks.
    Its experiment is read under the write lock (``locked``), so a concurrent delete of it waits
    for this commit (and then refuses: the experiment has a job) or has removed it first (404)."""
    if body.experiment_id is not None:
        locked(session, Experiment, body.experiment_id, "experiment")
    spec = spec_of(body)  # stored as its own versioned record: job_specs.py says why
    job = Job(
        experiment_id=body.experiment_id,
        kind=spec.kind,
        spec=encode(spec),
        state="queued",
        total=len(spec.zeta0s) * spec.trials if spec.kind == "mjtf" else 1,
        code_version=current_code_version(),
    )
    session.add(job)
    session.commit()
    return job


def get_job(session: Session, job_id: int) -> Job:
    return fetch(session, Job, job_id, "job")


def list_jobs(
    session: Session, *, state: str | None, limit: int, cursor: int | None, experiment_id: int | None = None
) -> tuple[list[Job], int | None]:
    query = newest_first(Job, limit, cursor)
    if state is not None:
        query = query.where(Job.state == state)
    if experiment_id is not None:
        query = query.where(Job.experiment_id == experiment_id)
    return page(list(session.scalars(query)), limit)


def cancel_job(session: Session, job_id: int) -> Job:
    """Queued jobs stop at once; running ones before their next chunk. Finished jobs are left as they are.

    Each change is one conditional UPDATE, so a job that the runner finishes while this request
    runs stays finished (reading the state and then writing it could overwrite "done").
    """
    job = get_job(session, job_id)
    for was, becomes in (
        ("queued", {"state": "cancelled", "finished_at": utcnow()}),
        ("running", {"state": "cancelling"}),
    ):
        session.execute(
            update(Job).where(Job.id == job_id, Job.state == was).values(**becomes),
            execution_options={"synchronize_session": False},
        )
    session.commit()
    session.refresh(job)
    return job


def level_summaries(session: Session, job: Job) -> list[dict]:
    """Per level: trials so far, mean and standard deviation of jumps to failure, outcomes —
    counted and summed by the database (one GROUP BY), not by reading every trial."""
    spec = decode(job.spec)
    groups = session.execute(
        select(
            Trial.level, Trial.failure_code, func.count(), func.sum(Trial.jumps), func.sum(Trial.jumps * Trial.jumps)
        )
        .where(Trial.job_id == job.id)
        .group_by(Trial.level, Trial.failure_code)
    ).all()
    counts = [{"capped": 0} | {f.code: 0 for f in Failure} for _ in spec.zeta0s]
    sums = [[0, 0, 0] for _ in spec.zeta0s]  # trials, sum of jumps, sum of squares: exact integers
    for level, code, trials, total, squares in groups:
        counts[level]["capped" if code is None else code] += trials
        for k, value in enumerate((trials, total, squares)):
            sums[level][k] += int(value)  # PostgreSQL sums integers as numeric: the same JSON either way
    summaries = []
    for level, zeta0 in enumerate(spec.zeta0s):
        trials, total, squares = sums[level]
        variance = (
            (trials * squares - total * total) / (trials * (trials - 1)) if trials > 1 else 0.0
        )  # exact numerator
        summaries.append(
            {
                "zeta0": zeta0,
                "trials": trials,
                "mean": total / trials if trials else float("nan"),
                "std": math.sqrt(max(variance, 0.0)),
                "outcomes": counts[level],
            }
        )
    return summaries


class _Stopped(Exception):
    """The runner is stopping while a job waits for disk space."""


class JobRunner:
    """Runs jobs one at a time on a background thread, resuming unfinished ones at start."""

    def __init__(
        self,
        sessions: sessionmaker[Session],
        pool: ComputePool,
        *,
        chunk_trials: int = CHUNK_TRIALS,
        dask_address: str | None = None,
    ):
        self.sessions = sessions
        self.pool = pool  # the job worker: chunks run there, not in this process
        self.chunk_trials = chunk_trials
        self.dask_address = dask_address
        self.queue: queue.Queue[int | None] = queue.Queue()
        self.thread: threading.Thread | None = None
        self._stopping = threading.Event()  # set by stop(): a job paused on a full disk gives up its wait

    def start(self) -> None:
        with self.sessions() as session:
            # A job that was running when the process died is picked up again from its trials.
            session.execute(update(Job).where(Job.state == "running").values(state="queued"))
            session.execute(
                update(Job).where(Job.state == "cancelling").values(state="cancelled", finished_at=utcnow())
            )
            session.commit()
            pending = list(session.scalars(select(Job.id).where(Job.state == "queued").order_by(Job.id)))
        for job_id in pending:
            self.queue.put(job_id)
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
        while (job_id := self.queue.get()) is not None:
            try:
                self.run(job_id)
            except _Stopped:  # paused on a full disk at shutdown: still running, the next start resumes it
                return
            except Exception as error:  # a job's failure is recorded; the runner goes on
                log.exception("job %s failed", job_id)
                with self.sessions() as session:
                    job = session.get(Job, job_id)
                    if job is not None:
                        job.state, job.error, job.finished_at = "failed", f"{type(error).__name__}: {error}", utcnow()
                        session.commit()

    def run(self, job_id: int) -> None:
        """Run (or resume) one job to its end, committing every chunk."""
        with self.sessions() as session:
            # Claimed with one conditional UPDATE, as cancel_job changes state: a cancel that lands
            # between reading the job and writing "running" is not overwritten.
            claimed = session.execute(
                update(Job)
                .where(Job.id == job_id, Job.state.in_(("queued", "running")))
                .values(state="running", started_at=func.coalesce(Job.started_at, utcnow())),
                execution_options={"synchronize_session": False},
            ).rowcount
            session.commit()
            if not claimed:
                return
            job = session.get(Job, job_id)
            kind, spec = job.kind, decode(job.spec)
        if kind != "mjtf":
            self._run_study(job_id, spec)
            return
        from sim_core.mjtf import level_starts  # the kernels load with the first job (simulation.py says why)

        model = model_params(spec.model)
        noise = NoiseModel(**asdict(spec.noise))
        guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
        try:
            starts = self.pool.submit(functools.partial(level_starts, guess=guess), model, np.radians(spec.psi0_deg),
                                      spec.zeta0s)  # fmt: skip
            levels = self._await(job_id, starts)
        except Cancelled:
            self._cancelled(job_id)  # marks it cancelled
            return
        chunks, arguments = [], []
        for index, level in enumerate(levels):
            seeds = trial_seeds(spec.seed, index, spec.trials)
            for chunk in self._missing_chunks(job_id, index, spec.trials):
                chunks.append((index, level.zeta0, chunk, seeds[chunk]))
                arguments.append((model, level.schedule, level.start, noise, seeds[chunk], spec.cap))
        if self._cancelled(job_id):
            return
        results = self._execute(job_id, arguments)
        try:
            for chunk, (jumps, status) in results:
                level, zeta0, indices, seeds = chunks[chunk]
                self._until_stored(job_id, self._commit_chunk, job_id, level, zeta0, indices, seeds, jumps, status)
                if self._cancelled(job_id):
                    return
        except Cancelled:
            self._cancelled(job_id)  # marks it cancelled
            return
        finally:
            results.close()  # on a Dask cluster, cancels the chunks not yet finished
        with self.sessions() as session:
            job = session.get(Job, job_id)
            job.state, job.finished_at = "done", utcnow()
            session.commit()

    def _run_study(self, job_id: int, spec) -> None:
        """Sweeps, basins and gait searches: computed whole (a restart recomputes them — they are
        deterministic), chunked through the chunk map, progress per chunk, result stored at the end."""

        def progress(done: int, total: int) -> None:
            with self.sessions() as session:
                job = session.get(Job, job_id)
                if job.state == "cancelling":
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
                job = session.get(Job, job_id)
                job.state, job.finished_at = "cancelled", utcnow()
                session.commit()
            return
        self._until_stored(job_id, self._store_result, job_id, json_safe(result))

    def _store_result(self, job_id: int, result: dict) -> None:
        with self.sessions() as session:
            job = session.get(Job, job_id)
            job.result = result
            job.completed = job.total
            job.state, job.finished_at = "done", utcnow()
            session.commit()

    def _until_stored(self, job_id: int, write: Callable, *args) -> None:
        """``write(*args)`` (one transaction), again every STORAGE_RETRY while the disk is full: the
        job pauses with what it computed in memory, and goes on when space returns."""
        paused = False
        while True:
            try:
                write(*args)
            except StorageFull:
                after_storage_full(self.sessions.kw["bind"])
                if not paused:
                    log.warning("job %s paused: the disk holding the database is full; it goes on when there is room",
                                job_id)  # fmt: skip
                    paused = True
                if self._stopping.wait(STORAGE_RETRY):
                    raise _Stopped from None
                continue
            if paused:
                log.warning("job %s goes on: its results fit again", job_id)
            return

    def _execute(self, job_id: int, arguments: list[tuple]) -> Iterator[tuple[int, tuple[np.ndarray, np.ndarray]]]:
        """``(chunk index, result)`` as chunks finish: from the job worker in order, a few handed
        to it ahead, or from the Dask cluster. Raises Cancelled (the worker stopped) on a cancel."""
        from sim_core.mjtf import run_trials

        if self.dask_address is not None:
            with dask_client(self.dask_address) as client:
                yield from as_completed_results(client, run_trials, arguments)
            return
        in_flight: dict[int, concurrent.futures.Future] = {}
        for index in range(len(arguments)):
            for ahead in range(index, min(index + IN_FLIGHT, len(arguments))):
                if ahead not in in_flight:
                    in_flight[ahead] = self.pool.submit(run_trials, *arguments[ahead])
            yield index, self._await(job_id, in_flight.pop(index))

    def _await(self, job_id: int, future: concurrent.futures.Future, progress: Callable | None = None):
        """The worker's result, looking every CANCEL_POLL for a cancel (then the worker is stopped
        and Cancelled raised) and passing on the progress it reports."""
        while True:
            try:
                return future.result(CANCEL_POLL)
            except concurrent.futures.TimeoutError:
                pass
            finally:
                for done, total in self.pool.progress() if progress is not None else ():
                    progress(done, total)
            if self._cancel_requested(job_id):
                self.pool.restart(f"job {job_id} was cancelled")
                raise Cancelled

    def _cancel_requested(self, job_id: int) -> bool:
        with self.sessions() as session:
            return session.scalar(select(Job.state).where(Job.id == job_id)) == "cancelling"

    def _missing_chunks(self, job_id: int, level: int, trials: int) -> list[np.ndarray]:
        with self.sessions() as session:
            done = set(session.scalars(select(Trial.index).where(Trial.job_id == job_id, Trial.level == level)))
        missing = np.array([i for i in range(trials) if i not in done], dtype=np.int64)
        return [missing[i : i + self.chunk_trials] for i in range(0, missing.size, self.chunk_trials)]

    def _cancelled(self, job_id: int) -> bool:
        with self.sessions() as session:
            job = session.get(Job, job_id)
            if job.state == "cancelling":
                job.state, job.finished_at = "cancelled", utcnow()
                session.commit()
                return True
            return job.state != "running"

    def _commit_chunk(self, job_id, level, zeta0, indices, seeds, jumps, status) -> None:
        with self.sessions() as session:
            session.add_all(
                Trial(
                    job_id=job_id,
                    level=level,
                    index=int(i),
                    zeta0=float(zeta0),
                    seed=int(seed),
                    jumps=int(n),
                    failure_code=None if code == OK else Failure(int(code)).code,
                )
                for i, seed, n, code in zip(indices, seeds, jumps, status, strict=True)
            )
            session.flush()
            completed = session.scalar(select(func.count()).select_from(Trial).where(Trial.job_id == job_id))
            session.execute(update(Job).where(Job.id == job_id).values(completed=completed, updated_at=utcnow()))
            session.commit()
