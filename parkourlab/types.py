"""The shapes of what the API answers, as the client hands them on: plain dicts (JSON as it
came), typed for editors and type checkers. The service's OpenAPI document (``/openapi.json``)
is the reference; each of these names every field of its answer, held to the API's response
models by tests/parkourlab/test_types.py. Nothing is checked at run time."""

from __future__ import annotations

from datetime import datetime
from typing import Any, Generic, Literal, TypedDict, TypeVar

T = TypeVar("T")
RunKind = Literal["sim", "robot", "replay"]
RunStatus = Literal["done", "failed", "running", "interrupted"]
RunLoop = Literal["open", "closed"]
JobState = Literal["queued", "running", "cancelling", "cancelled", "done", "failed"]
FINAL_JOB_STATES: frozenset[str] = frozenset({"done", "cancelled", "failed"})


class Page(TypedDict, Generic[T]):
    """One page of a list: its ``items`` and ``next_cursor`` (None on the last page). Sorted by id,
    pass it back as ``cursor``; sorted by another field, as ``offset``. ``total``: how many items
    match over every page, where the list counts them (None: not counted)."""

    items: list[T]
    next_cursor: int | None
    total: int | None


class Run(TypedDict):
    """A run as listed. ``model``: the nondimensional model (alpha, d_hat, c_zeta, c_psi, mu;
    docs/model.md §1); ``controls``: ``[psi0 [deg], zeta0 [l0]]`` per leg of the schedule;
    ``start_state``: ``[xdot, ydot]`` [sqrt(g l0)]; ``climb`` [l0]; ``duration_s`` [s]. A robot run
    also has its ``end_reason`` (as recorded) and ``touchdowns``; a closed loop (``loop``) its
    ``controller`` and ``target`` height [m]; None where they do not apply. ``created_by``: the
    person who made it, ``notes_by`` who last wrote its notes or tags (None: before people had names)."""

    id: int
    experiment_id: int | None
    world_id: int | None
    kind: RunKind
    status: RunStatus
    created_at: str
    duration_s: float
    code_version: str
    model: dict[str, Any]
    controls: list[list[float]]
    start_state: list[float]
    jumps: int
    jumps_completed: int
    failure_code: str | None
    climb: float
    tags: list[str]
    notes: str
    has_trajectory: bool
    end_reason: str | None
    loop: RunLoop
    controller: str | None
    target: float | None
    touchdowns: int | None
    created_by: str | None
    notes_by: str | None


class RunDetail(Run):
    """A run in full: with its ``results`` (section states, ``rises`` per jump [l0], ``failure``)."""

    results: dict[str, Any]


class Experiment(TypedDict):
    """An experiment: a named folder of runs and jobs; ``runs`` counts its runs."""

    id: int
    name: str
    description: str
    notes: str
    tags: list[str]
    created_at: str
    updated_at: str
    runs: int


class World(TypedDict):
    """A stored world: ``world`` is its §8 JSON as posted; ``source`` "posted", "named:NAME" or
    "random:SEED"; ``runs`` and ``jobs`` count those that use it."""

    id: int
    name: str
    world: dict[str, Any]
    source: str
    created_at: str
    created_by: str | None
    runs: int
    jobs: int


class Job(TypedDict):
    """A batch job. ``completed`` of ``total`` units (trials for MJTF) are done; ``progress`` is
    their ratio in [0, 1]; ``spec`` is the job's body with the service's defaults filled in.
    ``submitted_by``: the person who submitted it (their token's), ``submitted_via`` the tool (its
    ``X-Parkour-Client`` label); ``queue_position``
    (1: next), ``eta_s`` [s] until it should end (as expected on the service's machine) and
    ``eta_max_s`` [s] until it ends at the latest: None once it is final."""

    id: int
    experiment_id: int | None
    world_id: int | None
    kind: str
    state: JobState
    total: int
    completed: int
    progress: float
    error: str | None
    spec: dict[str, Any]
    created_at: str
    started_at: str | None
    finished_at: str | None
    submitted_by: str | None
    submitted_via: str | None
    queue_position: int | None
    eta_s: float | None
    eta_max_s: float | None


class MJTFLevel(TypedDict):
    """One energy level of an MJTF job: ``zeta0`` [l0], its ``trials``, the ``mean`` and ``std``
    of the jumps to failure, and how many trials ended each way (``outcomes``: ``capped`` or a
    failure code → count)."""

    zeta0: float
    trials: int
    mean: float
    std: float
    outcomes: dict[str, int]


class JobResults(TypedDict):
    """A job's results: ``partial`` until it is done; ``levels`` and ``missing_zeta0s`` for MJTF,
    ``result`` (the study's JSON) for the other kinds."""

    job: Job
    partial: bool
    levels: list[MJTFLevel] | None
    missing_zeta0s: list[float] | None
    result: dict[str, Any] | None


class RunFilters(TypedDict, total=False):
    """The filters every run query takes (list, export, aggregate, frame). Ranges are inclusive:
    zeta0 [l0] in [0, 1], psi0 [deg] in [0, 90] (the first leg's); datetimes or ISO 8601 text.
    ``end_reason``: as recorded, or its kind (``error`` matches ``error: …``); ``q``: text in the
    notes or a tag (any case, 3 characters or more); ``ids``: these runs only (up to 1,000)."""

    experiment_id: int
    world_id: int
    kind: RunKind
    status: RunStatus
    tag: str
    failure_code: str
    end_reason: str
    loop: RunLoop
    controller: str
    q: str
    ids: list[int]
    zeta0_min: float
    zeta0_max: float
    psi0_min: float
    psi0_max: float
    created_after: datetime | str
    created_before: datetime | str


RUN_FILTERS: frozenset[str] = frozenset(RunFilters.__annotations__)
