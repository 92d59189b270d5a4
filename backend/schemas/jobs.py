"""Batch jobs: the kinds a client can ask for (MJTF, energy sweep, basin, gait search, control
study, the MFPT of a gait or of a controller (backend/schemas/mfpt_jobs.py), viability), each
bounded by a work budget, and what a job and its results look like."""

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
    NominalPsi0Deg,
    Page,
    Psi0Deg,
    RecordRef,
    StateIn,
    Strict,
    TargetHeightM,
    Zeta0,
)
from backend.schemas.job_budget import (
    BASIN_JUMP_LIMIT,
    JUMP_LIMIT_DESCRIPTION,
    VIABILITY_MAX_ACTIONS,
    VIABILITY_MAX_STATES,
    within_budget,
)
from backend.schemas.mfpt_jobs import LoopMfptJobCreate, MfptJobCreate
from backend.schemas.noise import NoiseIn
from sim_core.control.laws import KINDS
from sim_core.viability.grid import DEFAULT_PSI0_DEG, DEFAULT_ZETA0

CLIENT_PATTERN = r"^[\w.:@/-]{1,64}$"  # the X-Parkour-Client header: who submits, for the queue's fairness


class JobState(enum.StrEnum):
    QUEUED = "queued"
    RUNNING = "running"
    CANCELLING = "cancelling"
    CANCELLED = "cancelled"
    DONE = "done"
    FAILED = "failed"


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
        return within_budget(self)


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
    basin_jump_limit: Annotated[int, Field(ge=1, le=BASIN_JUMP_LIMIT, description=JUMP_LIMIT_DESCRIPTION)] | None = None
    guess: StateIn | None = None

    @model_validator(mode="after")
    def _ordered(self) -> SweepJobCreate:
        if not self.zeta0_low < self.zeta0_high:
            raise ValueError(f"zeta0_low must be below zeta0_high, got {self.zeta0_low:g} >= {self.zeta0_high:g}")
        if self.basin_grid == 1:
            raise ValueError("basin_grid must be 0 (no basins) or at least 2")
        return within_budget(self)


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
    jump_limit: Annotated[int, Field(ge=1, le=BASIN_JUMP_LIMIT, description=JUMP_LIMIT_DESCRIPTION)] | None = None
    tolerance: Annotated[float, Field(gt=0.0, lt=10.0)] = 0.02

    @model_validator(mode="after")
    def _within_budget(self) -> BasinJobCreate:
        return within_budget(self)


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
    target_m: TargetHeightM = 0.55
    psi0_deg: NominalPsi0Deg = 35.0
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
        return within_budget(self)


ViabilityPsi0 = Annotated[float, Field(ge=1.0, le=89.0, description="leg angle [deg]")]
ViabilityZeta0 = Annotated[float, Field(ge=0.05, le=0.999, description="leg length [l0]")]


class ViabilityJobCreate(Strict):
    """The viability kernel and its measure (``parkour viability``): ``states`` nodes per mid-chute
    velocity axis over the default window, ``actions`` per control axis over the given ranges."""

    kind: Literal["viability"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    states: Annotated[int, Field(ge=4, le=VIABILITY_MAX_STATES, description="nodes per velocity axis")] = 40
    actions: Annotated[int, Field(ge=2, le=VIABILITY_MAX_ACTIONS, description="nodes per control axis")] = 16
    psi0_low_deg: ViabilityPsi0 = DEFAULT_PSI0_DEG[0]
    psi0_high_deg: ViabilityPsi0 = DEFAULT_PSI0_DEG[1]
    zeta0_low: ViabilityZeta0 = DEFAULT_ZETA0[0]
    zeta0_high: ViabilityZeta0 = DEFAULT_ZETA0[1]

    @model_validator(mode="after")
    def _ordered(self) -> ViabilityJobCreate:
        for low, high in (("psi0_low_deg", "psi0_high_deg"), ("zeta0_low", "zeta0_high")):
            if not getattr(self, low) < getattr(self, high):
                raise ValueError(f"{low} must be below {high}")
        return within_budget(self)


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
    | Annotated[ControlStudyJobCreate, KindTag("control-study")]
    | Annotated[MfptJobCreate, KindTag("mfpt")]
    | Annotated[LoopMfptJobCreate, KindTag("loop-mfpt")]
    | Annotated[ViabilityJobCreate, KindTag("viability")],
    Discriminator(_job_kind),
]
JOB_KINDS = {"mjtf": MJTFJobCreate, "sweep": SweepJobCreate, "basin": BasinJobCreate, "gaits": GaitSearchJobCreate,
             "control-study": ControlStudyJobCreate, "mfpt": MfptJobCreate, "loop-mfpt": LoopMfptJobCreate,
             "viability": ViabilityJobCreate}  # fmt: skip


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
