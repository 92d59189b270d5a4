"""A study job's computation — any registered kind with a run (:mod:`backend.jobs`) — as the job
runner hands it to its worker (:mod:`backend.services.job_runner`): the spec's model resolved, its
kind's run called with the chunk map and the progress.

Module-level and picklable, like the quick calls; the kernels load inside the runs.
"""

from __future__ import annotations

import math

from backend.jobs import KINDS, JobContext, job_kind, spec_of
from backend.services.presets import resolve_model
from backend.workers.progress import report


def run_study_here(spec) -> dict:
    """:func:`run_study` in the job worker: its chunks one after the other there (each uses every
    core), progress reported to the service (:func:`backend.workers.progress.report`)."""
    from sim_core.chunks import in_process

    return run_study(spec, in_process, report)


def run_study(spec, chunk_map, progress) -> dict:
    """The job's computation by its kind's run; its JSON result. ``progress(done, total)`` raises
    Cancelled on a cancel."""
    robot = resolve_model(None, spec.model.preset).robot  # a stored preset is resolved already
    context = JobContext(spec.model.params(), robot, chunk_map, progress)
    return job_kind(spec.kind).run(spec, context)


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
        spec = spec_of(kind.request(**({"kind": kind.name} | kind.warm)))
        if kind.run is not None:
            run_study(spec, in_process, _no_progress)
        else:
            from sim_core.robustness.mjtf import mjtf_study

            mjtf_study(spec.model.params(), math.radians(spec.psi0_deg), spec.zeta0s, noise=spec.noise.model(),
                       trials=spec.trials, cap=spec.cap)  # fmt: skip


def _no_progress(done: int, total: int) -> None:
    pass
