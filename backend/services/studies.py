"""A study job's computation — any registered kind with a run (:mod:`backend.jobs`) — as the job
runner hands it to its worker (:mod:`backend.services.job_runner`): the spec's model resolved, its
kind's run called with the chunk map and the progress.

Module-level and picklable, like the quick calls; the kernels load inside the runs.
"""

from __future__ import annotations

from backend.jobs import JobContext, job_kind
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
