"""An energy sweep (``parkour sweep``): the symmetric gait followed over zeta0, with its basin areas."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase
from backend.jobs.budget import BASIN_JUMP_LIMIT, JUMP_LIMIT_DESCRIPTION, basin_cell_jumps, within_budget
from backend.jobs.specs import ModelSpec, StateSpec
from backend.schemas.common import ModelIn, Psi0Deg, RecordRef, StateIn, Strict, Zeta0
from sim_core.basins.grid import DEFAULT_BASIN_WINDOW, BasinGrid


def worst_case(job) -> WorstCase:
    cell, name = basin_cell_jumps(job.basin_jumps, job.basin_jump_limit, "basin_jumps", "basin_jump_limit")
    return job.steps * job.basin_grid**2 * cell, f"steps x basin_grid² x {name}"


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
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class SweepSpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_deg: float = 30.0
    zeta0_low: float = 0.8
    zeta0_high: float = 0.97
    steps: int = 30
    basin_grid: int = 40
    basin_jumps: int = 60
    basin_jump_limit: int | None = None
    guess: StateSpec | None = None
    kind: str = "sweep"


def run(spec: SweepSpec, context: JobContext) -> dict:
    """``parkour sweep --json``'s figures, its basins chunked through the chunk map."""
    from sim_core.basins.sweep import energy_sweep, zeta0_values

    grid = None if spec.basin_grid == 0 else BasinGrid(*DEFAULT_BASIN_WINDOW, spec.basin_grid)
    guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
    sweep = energy_sweep(
        context.model,
        math.radians(spec.psi0_deg),
        zeta0_values(spec.zeta0_low, spec.zeta0_high, spec.steps),
        guess=guess,
        basin_grid=grid,
        basin_jumps=spec.basin_jumps,
        basin_jump_limit=spec.basin_jump_limit,
        chunk_map=context.chunk_map,
        progress=context.progress,
    )
    return sweep.to_dict()


KIND = JobKind(
    "sweep",
    "zeta0 sweep",
    SweepJobCreate,
    SweepSpec,
    worst_case,
    run,
    typical_fraction=0.077,
    warm={"steps": 2, "basin_grid": 2, "basin_jumps": 2},
)
