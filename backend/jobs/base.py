"""What every job kind is made of (:class:`JobKind`) and what its run is handed (:class:`JobContext`)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import ParameterError

if TYPE_CHECKING:
    from sim_core.model.params import ModelParams, PhysicalParams

WorstCase = tuple[int, str]  # a job's work in jumps at its worst, and the formula that counts it


@dataclass(frozen=True)
class JobContext:
    """What a job's run is handed: its ``model`` (the request's preset and overrides), the preset's
    ``robot`` (SI; the leg length turns metres into l0), the ``chunk_map`` its chunks go through (the
    job worker's, or a Dask cluster's) and ``progress(done, total)``, which raises Cancelled on a cancel."""

    model: ModelParams
    robot: PhysicalParams
    chunk_map: Callable
    progress: Callable[[int, int], None]


def one_chunk(spec: Any) -> int:
    """A job counted as one piece of work (it reports its progress as fractions)."""
    return 1


@dataclass(frozen=True)
class Chunked:
    """A kind whose work is independent chunks, each stored as it finishes, so that a restart (after a
    kill -9 too) computes only those missing and ends with the result an uninterrupted job gives
    (:meth:`backend.services.job_runner.JobRunner.run`). ``arguments(spec, context)``: each chunk's
    arguments, in order; ``chunk(*arguments)``: one chunk's JSON result (module-level: it runs in the
    job worker, or on a Dask worker); ``combine(spec, context, results)``: the job's result from every
    chunk's (as stored: JSON), in order. All three run in the job worker, never in the service."""

    arguments: Callable[[Any, JobContext], list[tuple]]
    chunk: Callable[..., dict]
    combine: Callable[[Any, JobContext, list[dict]], dict]


@dataclass(frozen=True)
class JobKind:
    """A registered job kind (:mod:`backend.jobs`): its ``name`` (the request's ``kind``), a
    ``title`` for choosers, its ``request`` body (a strict pydantic model, checked against the
    work budget), its stored ``spec`` (a frozen dataclass, :mod:`backend.jobs.specs`), its
    ``worst_case`` work (of a request or a spec alike), its ``run`` (spec, :class:`JobContext`) ->
    JSON result, in the job worker — None for a kind the runner runs trial by trial (MJTF) — and
    its ``total`` pieces of work (what ``completed`` counts up to). ``typical_fraction``: what such a
    job takes, as a share of its worst case at the job worker's rate, before this machine has run
    one (measured by scripts/bench_job_estimates.py; the service learns its own from finished jobs,
    :mod:`backend.services.job_estimates`). ``warm``: a small request body (its fields but ``kind``)
    whose run loads the kind's kernels: the job worker runs each at start, so that a first job does
    not wait for them (an MFPT took 11 s cold, 5.6 s warm). ``chunked``: for a kind run chunk by
    chunk, each stored (:class:`Chunked`; its ``run`` is None). ``check(spec, robot)``: what the
    request's schema cannot check alone, once its stored world is in the spec (a goal within the
    world): a ParameterError naming the field."""

    name: str
    title: str
    request: type
    spec: type
    worst_case: Callable[[Any], WorstCase]
    run: Callable[[Any, JobContext], dict] | None
    total: Callable[[Any], int] = one_chunk
    typical_fraction: float = 1.0
    warm: dict | None = None
    chunked: Chunked | None = None
    check: Callable[[Any, PhysicalParams], None] | None = None


@contextmanager
def gait_not_found_as_parameter_error() -> Iterator[None]:
    """A gait search that finds nothing is a 422 naming the controls (a guess may find one)."""
    from sim_core.model.errors import NoGaitFound

    try:
        yield
    except NoGaitFound as error:
        message = f"no period-{error.period} gait found from a grid of guesses; give a guess"
        raise ParameterError("controls", message) from None


def schedule_of(controls) -> ControlSchedule:
    """A request's or a stored spec's legs (each with ``psi0_deg`` and ``zeta0``), in order, as a control schedule."""
    return ControlSchedule.from_degrees([(leg.psi0_deg, leg.zeta0) for leg in controls])
