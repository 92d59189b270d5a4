"""The basin of attraction of a gait over a grid of section states (``parkour basin``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase, gait_not_found_as_parameter_error, schedule_of
from backend.jobs.budget import BASIN_JUMP_LIMIT, JUMP_LIMIT_DESCRIPTION, basin_cell_jumps, within_budget
from backend.jobs.specs import LegSpec, ModelSpec, StateSpec
from backend.schemas.common import LegIn, ModelIn, RecordRef, StateIn, Strict


def worst_case(job) -> WorstCase:
    cell, name = basin_cell_jumps(job.jumps, job.jump_limit, "jumps", "jump_limit")
    return job.grid**2 * cell, f"grid² x {name}"


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
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class BasinSpec:
    controls: tuple[LegSpec, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    period: int | None = None
    guess: StateSpec | None = None
    grid: int = 100
    jumps: int = 60
    jump_limit: int | None = None
    tolerance: float = 0.02
    kind: str = "basin"


def run(spec: BasinSpec, context: JobContext) -> dict:
    """``parkour basin --json``'s figures, its cells chunked through the chunk map."""
    from experiments.gait_basin import gait_basin

    guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
    with gait_not_found_as_parameter_error():
        basin = gait_basin(
            context.model,
            schedule_of(spec.controls),
            period=spec.period,
            guess=guess,
            grid=spec.grid,
            max_jumps=spec.jumps,
            tolerance=spec.tolerance,
            jump_limit=spec.jump_limit,
            chunk_map=context.chunk_map,
            progress=context.progress,
        )
    return basin.to_dict()


KIND = JobKind(
    "basin",
    "basin grid",
    BasinJobCreate,
    BasinSpec,
    worst_case,
    run,
    typical_fraction=0.072,
    warm={"controls": [{"psi0_deg": 30.0, "zeta0": 0.9}], "grid": 2, "jumps": 2},
)
