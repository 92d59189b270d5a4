"""Batch jobs: the kinds a client can ask for (MJTF, energy sweep, basin, gait search, control
study), each bounded by a work budget, and what a job and its results look like."""

from __future__ import annotations

import datetime
import enum
from typing import Annotated, Literal

from pydantic import BaseModel, Discriminator, Field, field_validator, model_validator
from pydantic import Tag as KindTag

from backend.schemas.common import (
    MAX_LEVELS,
    MAX_TRIALS,
    LegIn,
    ModelIn,
    Page,
    Psi0Deg,
    RecordRef,
    StateIn,
    Strict,
    Zeta0,
)
from sim_core.climb_records import CHUTE_TOP, FLOOR
from sim_core.control_laws import KINDS, PSI0_RANGE_DEG
from sim_core.noise import ASYMMETRY_LIMITS, SIGMA_LIMITS, NoiseModel

# A job's work, in jumps at its worst (every trial to its cap, every basin point to its jump limit):
# about an hour of the job worker on the lab's machine (1.35e5-1.6e5 jumps/s measured by
# scripts/bench_job_rate.py on 2 cores). Larger jobs are refused with a 422 naming the limit.
WORK_BUDGET_JUMPS = 500_000_000
# The queue's budget: queued and running work together (each job at its worst, a running one's
# share still to do), about eight hours of the job worker; one client (a script, the panel) may
# hold at most CLIENT_SHARE of it, so another always finds room. Past either, a 429 says so.
QUEUE_BUDGET_JUMPS = 8 * WORK_BUDGET_JUMPS
CLIENT_SHARE = 0.5
MAX_QUEUED_JOBS = 1000  # jobs waiting at once, however small
JOB_RATE_JUMPS_PER_S = 135_000  # the job worker's rate (the low end of scripts/bench_job_rate.py): for estimates
GAIT_SEARCH_JUMPS = 1000  # a gait search's work per guess, at most (Levenberg–Marquardt's map evaluations)
CLIENT_PATTERN = r"^[\w.:@/-]{1,64}$"  # the X-Parkour-Client header: who submits, for the queue's fairness


class JobState(enum.StrEnum):
    QUEUED = "queued"
    RUNNING = "running"
    CANCELLING = "cancelling"
    CANCELLED = "cancelled"
    DONE = "done"
    FAILED = "failed"


_NOISE = NoiseModel()  # the noise's defaults; its ranges: SIGMA_LIMITS, ASYMMETRY_LIMITS (sim_core.noise)


class NoiseIn(Strict):
    psi0_deg: Annotated[float, Field(ge=0.0, lt=SIGMA_LIMITS["psi0_deg"])] = _NOISE.psi0_deg
    zeta0: Annotated[float, Field(ge=0.0, lt=SIGMA_LIMITS["zeta0"])] = _NOISE.zeta0
    velocity: Annotated[float, Field(ge=0.0, lt=SIGMA_LIMITS["velocity"])] = _NOISE.velocity
    pitch_drift_deg: Annotated[float, Field(ge=0.0, lt=SIGMA_LIMITS["pitch_drift_deg"])] = _NOISE.pitch_drift_deg
    asymmetry_psi0_deg: Annotated[
        float, Field(gt=-ASYMMETRY_LIMITS["asymmetry_psi0_deg"], lt=ASYMMETRY_LIMITS["asymmetry_psi0_deg"])
    ] = _NOISE.asymmetry_psi0_deg
    asymmetry_zeta0: Annotated[
        float, Field(gt=-ASYMMETRY_LIMITS["asymmetry_zeta0"], lt=ASYMMETRY_LIMITS["asymmetry_zeta0"])
    ] = _NOISE.asymmetry_zeta0


class MJTFJobCreate(Strict):
    """Mean Jumps To Failure: ``levels`` zeta0 values x ``trials`` noisy trials each."""

    kind: Literal["mjtf"] = "mjtf"
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    psi0_deg: Psi0Deg = 30.0
    zeta0s: Annotated[list[Zeta0], Field(min_length=1, max_length=MAX_LEVELS)]
    trials: Annotated[int, Field(ge=1, le=MAX_TRIALS)] = 8
    cap: Annotated[int, Field(ge=1, le=100_000)] = 1000
    seed: Annotated[int, Field(ge=0, lt=2**63)] = 0
    noise: NoiseIn = NoiseIn()
    guess: StateIn | None = None

    @field_validator("zeta0s")
    @classmethod
    def _distinct(cls, values: list[float]) -> list[float]:
        if len(set(values)) != len(values):
            raise ValueError("zeta0 values must be distinct")
        return values

    @model_validator(mode="after")
    def _within_budget(self) -> MJTFJobCreate:
        return _within_budget(self)


class SweepJobCreate(Strict):
    """An energy sweep: the gait followed over zeta0, with basin areas (``basin_grid`` 0: none)."""

    kind: Literal["sweep"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    psi0_deg: Psi0Deg = 30.0
    zeta0_low: Zeta0 = 0.8
    zeta0_high: Zeta0 = 0.97
    steps: Annotated[int, Field(ge=2, le=500)] = 30
    basin_grid: Annotated[int, Field(ge=0, le=200)] = 40
    basin_jumps: Annotated[int, Field(ge=1, le=1000)] = 60
    guess: StateIn | None = None

    @model_validator(mode="after")
    def _ordered(self) -> SweepJobCreate:
        if not self.zeta0_low < self.zeta0_high:
            raise ValueError(f"zeta0_low must be below zeta0_high, got {self.zeta0_low:g} >= {self.zeta0_high:g}")
        if self.basin_grid == 1:
            raise ValueError("basin_grid must be 0 (no basins) or at least 2")
        return _within_budget(self)


class BasinJobCreate(Strict):
    """The basin of attraction of a gait over a grid of section states."""

    kind: Literal["basin"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    guess: StateIn | None = None
    grid: Annotated[int, Field(ge=2, le=1000)] = 100
    jumps: Annotated[int, Field(ge=1, le=1000)] = 60
    tolerance: Annotated[float, Field(gt=0.0, lt=10.0)] = 0.02

    @model_validator(mode="after")
    def _within_budget(self) -> BasinJobCreate:
        return _within_budget(self)


class GaitSearchJobCreate(Strict):
    """Distinct gaits of one control schedule, from a grid of guesses."""

    kind: Literal["gaits"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    grid: Annotated[int, Field(ge=1, le=20)] = 6


class ControlStudyJobCreate(Strict):
    """The closed-loop benchmark (``parkour control-study``): each controller climbing to
    ``target_m`` on the same noise draws, ``seeds`` trials of ``jumps`` jumps each."""

    kind: Literal["control-study"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controllers: Annotated[
        list[str], Field(min_length=1, max_length=8, description=f"names, each once, of: {', '.join(KINDS)}")
    ] = ["pid", "pid-pitch", "lqr", "deadbeat"]
    target_m: Annotated[
        float, Field(gt=FLOOR, le=CHUTE_TOP, description="height to hold [m], above the floor, within the chute")
    ] = 0.55
    psi0_deg: Annotated[
        float, Field(ge=PSI0_RANGE_DEG[0], le=PSI0_RANGE_DEG[1], description="nominal leg angle [deg]")
    ] = 35.0
    start_zeta0: Zeta0 = 0.9
    jumps: Annotated[int, Field(ge=1, le=100_000)] = 400
    seeds: Annotated[int, Field(ge=1, le=MAX_TRIALS)] = 200
    seed0: Annotated[int, Field(ge=0, le=2**32 - MAX_TRIALS)] = 0
    noise: NoiseIn = NoiseIn()

    @field_validator("controllers")
    @classmethod
    def _known(cls, names: list[str]) -> list[str]:
        unknown = [name for name in names if name not in KINDS]
        if unknown:
            raise ValueError(f"must be among {', '.join(KINDS)}, got {unknown[0]!r}")
        if len(set(names)) != len(names):
            raise ValueError(f"names a controller twice: {', '.join(names)}")
        return names

    @model_validator(mode="after")
    def _within_budget(self) -> ControlStudyJobCreate:
        return _within_budget(self)


def worst_case_jumps(job) -> tuple[int, str]:
    """A job's work in jumps at its worst, and the formula that counts it: for a request body or a
    stored spec alike (both have the fields this reads)."""
    if job.kind == "mjtf":
        return len(job.zeta0s) * job.trials * job.cap, "levels x trials x cap"
    if job.kind == "sweep":
        return job.steps * job.basin_grid**2 * job.basin_jumps, "steps x basin_grid² x basin_jumps"
    if job.kind == "basin":
        return job.grid**2 * job.jumps, "grid² x jumps"
    if job.kind == "control-study":
        return len(job.controllers) * job.seeds * job.jumps, "controllers x seeds x jumps"
    return job.grid**2 * GAIT_SEARCH_JUMPS, f"grid² x {GAIT_SEARCH_JUMPS}"


def _within_budget(job):
    """``job`` if its worst-case work fits the budget."""
    jumps, formula = worst_case_jumps(job)
    if jumps > WORK_BUDGET_JUMPS:
        raise ValueError(
            f"the job would take up to {jumps:.3g} jumps ({formula}), over the limit of {WORK_BUDGET_JUMPS:.3g} "
            "(about an hour of the job worker); ask for less, or split it into several jobs"
        )
    return job


def _job_kind(value) -> str:
    """The job's ``kind``; MJTF when absent (the first kind, which clients may leave out)."""
    if isinstance(value, dict):
        return value.get("kind", "mjtf")
    return getattr(value, "kind", "mjtf")


JobCreate = Annotated[
    Annotated[MJTFJobCreate, KindTag("mjtf")]
    | Annotated[SweepJobCreate, KindTag("sweep")]
    | Annotated[BasinJobCreate, KindTag("basin")]
    | Annotated[GaitSearchJobCreate, KindTag("gaits")]
    | Annotated[ControlStudyJobCreate, KindTag("control-study")],
    Discriminator(_job_kind),
]
JOB_KINDS = {"mjtf": MJTFJobCreate, "sweep": SweepJobCreate, "basin": BasinJobCreate, "gaits": GaitSearchJobCreate,
             "control-study": ControlStudyJobCreate}  # fmt: skip


class JobOut(BaseModel):
    id: int
    experiment_id: int | None
    kind: str
    state: JobState
    total: int
    completed: int
    progress: float
    error: str | None
    spec: dict
    created_at: datetime.datetime
    started_at: datetime.datetime | None
    finished_at: datetime.datetime | None
    submitted_by: str | None = Field(None, description="who submitted it: X-Parkour-Client, else the address")
    queue_position: int | None = Field(None, description="1: runs next; null when not queued")
    eta_s: float | None = Field(
        None, description="seconds until it ends at the latest (its work and the work ahead at their worst)"
    )


JobPage = Page[JobOut]


class MJTFLevelOut(BaseModel):
    zeta0: float
    trials: int
    mean: float
    std: float
    outcomes: dict[str, int]


class JobResults(BaseModel):
    job: JobOut
    partial: bool = Field(description="not done (queued, running, cancelled or failed): not every trial is in")
    levels: list[MJTFLevelOut] | None = Field(None, description="MJTF jobs: the energy levels with trials so far")
    missing_zeta0s: list[float] | None = Field(None, description="MJTF jobs: the levels without a trial yet")
    result: dict | None = Field(None, description="other jobs: the study's result, once done")
