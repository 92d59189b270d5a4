"""Mean Jumps To Failure (``parkour mjtf``): ``levels`` zeta0 values x ``trials`` noisy trials each.
Run by the job runner trial by trial, so a crash loses no stored trial
(:meth:`backend.services.job_runner.JobRunner.run`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from backend.jobs.base import JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.specs import ModelSpec, NoiseSpec, StateSpec
from backend.schemas.common import MAX_LEVELS, MAX_TRIALS, ModelIn, Psi0Deg, RecordRef, StateIn, Strict, Zeta0
from backend.schemas.noise import NoiseIn


def worst_case(job) -> WorstCase:
    return len(job.zeta0s) * job.trials * job.cap, "levels x trials x cap"


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
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class MJTFSpec:
    zeta0s: tuple[float, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_deg: float = 30.0
    trials: int = 8
    cap: int = 1000
    seed: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    guess: StateSpec | None = None
    kind: str = "mjtf"


KIND = JobKind(
    "mjtf", "Mean Jumps To Failure", MJTFJobCreate, MJTFSpec, worst_case, run=None,
    total=lambda spec: len(spec.zeta0s) * spec.trials, typical_fraction=0.1,
    warm={"zeta0s": [0.9], "trials": 2, "cap": 20},
)  # fmt: skip
