"""Batch jobs, a module per kind, and the one registry that the runner, the API's job union, the
queue's budget, the catalog (and through it the panel and the Python client) read.

A kind's module holds all of it: its request body (a strict pydantic model, its ranges and its
work checked against the budget), its stored spec (a frozen dataclass, versioned with the others:
:mod:`backend.jobs.specs`), its worst-case work in jumps, its run (spec, :class:`JobContext`) ->
JSON result in the job worker, and a :class:`JobKind` ``KIND`` naming them. The runner, the queue
and the results read nothing else. Adding a kind: its module, its line in :data:`KINDS`, its test
(and a panel module only where its result is drawn in a new way).

Below the services, above the workers and the store: a kind's run is handed its model and chunk
map (:class:`JobContext`), so it needs no service.
"""

from __future__ import annotations

from typing import Annotated, Union

from pydantic import Discriminator
from pydantic import Tag as KindTag

from backend.jobs import (
    atlas,
    basin,
    control_study,
    foothold_study,
    gaits,
    loop_mfpt,
    mfpt,
    mjtf,
    plan,
    reach,
    sweep,
    viability,
    world_mjtf,
)
from backend.jobs.base import JobContext, JobKind, WorstCase
from backend.jobs.specs import UnreadableSpec, encode, read_fields

KINDS: tuple[JobKind, ...] = (mjtf.KIND, sweep.KIND, basin.KIND, gaits.KIND, control_study.KIND, mfpt.KIND,
                              loop_mfpt.KIND, viability.KIND, atlas.KIND, foothold_study.KIND,
                              plan.KIND, world_mjtf.KIND, reach.KIND)  # fmt: skip
BY_NAME: dict[str, JobKind] = {kind.name: kind for kind in KINDS}
JOB_KINDS: dict[str, type] = {kind.name: kind.request for kind in KINDS}  # the request body of each
DEFAULT_KIND = "mjtf"  # a request without a kind (the first kind, which clients may leave out)

__all__ = [
    "BY_NAME",
    "JOB_KINDS",
    "KINDS",
    "JobContext",
    "JobCreate",
    "JobKind",
    "UnreadableSpec",
    "decode",
    "encode",
    "job_kind",
    "spec_of",
    "worst_case_jumps",
]


def _job_kind(value) -> str:
    """The request's ``kind``; :data:`DEFAULT_KIND` when absent."""
    if isinstance(value, dict):
        return value.get("kind", DEFAULT_KIND)
    return getattr(value, "kind", DEFAULT_KIND)


# The API's job body: one of the registered kinds' requests, told apart by ``kind``.
JobCreate = Annotated[
    Union[tuple(Annotated[kind.request, KindTag(kind.name)] for kind in KINDS)],  # noqa: UP007 (built at run time)
    Discriminator(_job_kind),
]


def job_kind(name: str) -> JobKind:
    """The registered kind ``name``; an UnreadableSpec for a name this code does not know."""
    if name not in BY_NAME:
        raise UnreadableSpec(f"unknown job kind {name!r}")
    return BY_NAME[name]


def worst_case_jumps(job) -> WorstCase:
    """A job's work in jumps at its worst, and the formula that counts it: for a request body or a
    stored spec alike (both have the fields its kind reads)."""
    return job_kind(job.kind).worst_case(job)


def spec_of(body):
    """An accepted job request (any of :data:`JOB_KINDS`) as the spec the store keeps."""
    return decode(body.model_dump(mode="json"))


def decode(stored: dict):
    """A stored spec, version 1 or unversioned (0), as its kind's spec; fields it does not use
    (``experiment_id``) are left out, missing ones take the defaults of their day."""
    from backend.jobs.specs import SPEC_VERSION

    version = stored.get("version", 0)
    if version not in (0, SPEC_VERSION):
        raise UnreadableSpec(f"job spec version {version} is newer than this code (it reads up to {SPEC_VERSION})")
    return read_fields(job_kind(stored.get("kind", DEFAULT_KIND)).spec, stored)
