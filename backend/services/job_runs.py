"""The job runner's runs of the kinds that store their work as it goes — MJTF trial by trial, a
chunked kind chunk by chunk (:mod:`backend.services.job_runner` says how each resumes) — as the
methods of :class:`~backend.services.job_runner.JobRunner` they are: they use its sessions, its
worker (``_await``, ``_execute``), its writes that wait for disk space (``_stored``) and its
cancel checks (``_cancelled``)."""

from __future__ import annotations

import functools

import numpy as np

from backend.jobs import job_kind
from backend.jobs.mjtf import MJTFSpec
from backend.repositories import jobs as stored_jobs
from backend.schemas.jobs import JobState
from backend.services.studies import chunk_arguments, combine_chunks, trial_rows
from backend.store.models import utcnow
from experiments.manifest import json_safe
from sim_core.chunks import Cancelled
from sim_core.robustness.mjtf_plan import TrialChunk, plan_trials


class RunsByKind:
    """MJTF's and the chunked kinds' runs (mixed into the JobRunner)."""

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

    def _run_chunked(self, job_id: int, spec) -> None:
        """A chunked kind (:class:`backend.jobs.base.Chunked`): its chunks not stored yet, each
        committed as it finishes, then its result from every chunk's as stored (JSON), so that a
        resumed job's result is the one an uninterrupted job gives. Arguments and result are made
        in the job worker: their kernels stay out of the service's interpreter."""
        try:
            arguments = self._await(job_id, self.pool.submit(chunk_arguments, spec))
            with self.sessions() as session:
                stored = stored_jobs.stored_chunks(session, job_id)
            missing = [index for index in range(len(arguments)) if index not in stored]
            results = self._execute(job_id, job_kind(spec.kind).chunked.chunk, [arguments[i] for i in missing])
            try:
                for position, result in results:
                    index = missing[position]
                    stored[index] = json_safe(result)
                    self._stored(f"storing job {job_id}'s chunk {index}", self._commit_result_chunk, job_id, index,
                                 stored[index])  # fmt: skip
                    if self._cancelled(job_id):
                        return
            finally:
                results.close()  # on a Dask cluster, cancels the chunks not yet finished
            chunks = [stored[index] for index in range(len(arguments))]
            result = self._await(job_id, self.pool.submit(combine_chunks, spec, chunks))
        except Cancelled:
            self._cancelled(job_id)  # marks it cancelled
            return
        self._stored(f"storing job {job_id}'s result", self._store_result, job_id, json_safe(result))

    def _commit_result_chunk(self, job_id: int, index: int, result: dict) -> None:
        with self.sessions() as session:
            stored_jobs.add_chunk(session, job_id, index, result)
            session.commit()

    def _commit_chunk(self, job_id: int, chunk: TrialChunk, zeta0: float, jumps, status) -> None:
        with self.sessions() as session:
            stored_jobs.add_trials(session, job_id, trial_rows(job_id, chunk, zeta0, jumps, status))
            session.commit()
