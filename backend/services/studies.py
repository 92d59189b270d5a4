"""A study job's computation — any registered kind with a run (:mod:`backend.jobs`) — as the job
runner hands it to its worker (:mod:`backend.services.job_runner`): the spec's model resolved, its
kind's run called with the chunk map and the progress.

Module-level and picklable, like the quick calls; the kernels load inside the runs.
"""

from __future__ import annotations

import math

from backend.jobs import KINDS, JobContext, job_kind, spec_of
from backend.services.presets import resolve_model
from backend.store.models import Trial
from backend.workers.progress import report


def run_study_here(spec) -> dict:
    """:func:`run_study` in the job worker: its chunks one after the other there (each uses every
    core), progress reported to the service (:func:`backend.workers.progress.report`)."""
    from sim_core.chunks import in_process

    return run_study(spec, in_process, report)


def run_study(spec, chunk_map, progress) -> dict:
    """The job's computation by its kind's run; its JSON result. ``progress(done, total)`` raises
    Cancelled on a cancel."""
    return job_kind(spec.kind).run(spec, _context(spec, chunk_map, progress))


def chunk_arguments(spec) -> list[tuple]:
    """A chunked kind's chunks' arguments (:class:`backend.jobs.base.Chunked`), in the job worker."""
    return job_kind(spec.kind).chunked.arguments(spec, _context(spec, None, None))


def combine_chunks(spec, results: list[dict]) -> dict:
    """A chunked kind's result from its chunks' (as stored), in the job worker."""
    return job_kind(spec.kind).chunked.combine(spec, _context(spec, None, None), results)


def run_chunked_here(spec) -> dict:
    """A chunked kind's job whole, in this process, storing nothing (the warm-up)."""
    chunked = job_kind(spec.kind).chunked
    return combine_chunks(spec, [chunked.chunk(*arguments) for arguments in chunk_arguments(spec)])


def _context(spec, chunk_map, progress) -> JobContext:
    robot = resolve_model(None, spec.model.preset).robot  # a stored preset is resolved already
    return JobContext(spec.model.params(), robot, chunk_map, progress)


def warm_job_kinds() -> None:
    """What the job worker runs first: the quick calls' kernels, then each kind's small ``warm``
    job (its kernels loaded from numba's cache, or compiled once), so that a first job of a kind
    does not wait for them. MJTF, which the runner runs trial by trial, by its study."""
    from backend.services.quick_calls import warm_up
    from sim_core.chunks import in_process

    warm_up()
    for kind in KINDS:
        if kind.warm is None:
            continue
        spec = _in_a_warm_world(spec_of(kind.request(**({"kind": kind.name} | kind.warm))))
        if kind.chunked is not None:
            run_chunked_here(spec)
        elif kind.run is not None:
            run_study(spec, in_process, _no_progress)
        else:
            from sim_core.robustness.mjtf import mjtf_study

            mjtf_study(spec.model.params(), math.radians(spec.psi0_deg), spec.zeta0s, noise=spec.noise.model(),
                       trials=spec.trials, cap=spec.cap)  # fmt: skip


def _in_a_warm_world(spec):
    """A warm-up spec of a kind that works in a stored world, with the staircase as its world (the
    job worker reads no store)."""
    if getattr(spec, "world_id", None) is None:
        return spec
    from dataclasses import replace

    from sim_core.world.files import world_to_document
    from sim_core.world.named import named_world

    return replace(spec, world=world_to_document(named_world("staircase", spec.model.params().d_hat)))


def trial_rows(job_id: int, chunk, zeta0: float, jumps, status) -> list[Trial]:
    """An MJTF chunk's trials (:class:`sim_core.robustness.mjtf_plan.TrialChunk`) as the store's rows."""
    from sim_core.model.failures import OK, Failure

    return [Trial(job_id=job_id, level=chunk.level, index=int(i), zeta0=float(zeta0), seed=int(seed), jumps=int(n),
                  failure_code=None if code == OK else Failure(int(code)).code)
            for i, seed, n, code in zip(chunk.indices, chunk.seeds, jumps, status, strict=True)]  # fmt: skip


def _no_progress(done: int, total: int) -> None:
    pass
