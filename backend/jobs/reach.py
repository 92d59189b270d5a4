"""Reach in a stored world (``parkour reach``) as a job: over a grid of symmetric leg schedules
``psi0 x zeta0``, how high each climbs from touchdown 0 (the foot on the left side at ``foot_y``)
in up to ``jumps`` jumps with no noise, and how it ends — at the world's top, at the cap, or by a
failure (:func:`sim_core.world.reach.reach_map`, docs/model.md §8).

Chunked by blocks of :data:`CHUNK_ROWS` rows of ``zeta0`` (:func:`sim_core.world.reach.reach_chunks`),
each stored as it finishes: a restart computes only the rows missing, and the result — ``parkour
reach --json`` on the same world file and grid (its ``l0_m`` included) — is the uninterrupted job's
(a cell depends on its controls alone).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from backend.jobs.base import Chunked, JobContext, JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.in_world import WorldRef, label_of, world_of
from backend.jobs.specs import ModelSpec, StateSpec
from backend.schemas.common import ModelIn, Psi0Deg, RecordRef, StateIn, Strict, Zeta0

# sim_core.world.reach's limits and chunk, said again here: its module loads the kernels, which the
# API does not (tests/backend/jobs/test_reach.py holds them equal).
MAX_CELLS = 250_000  # a grid's cells (sim_core.world.reach.MAX_CELLS)
MAX_CELL_JUMPS = 25_000_000  # cells x jumps (sim_core.world.reach.MAX_CELL_JUMPS): about a minute on two cores
CHUNK_ROWS = 8  # zeta0 rows a chunk, a commit each (sim_core.world.reach.DEFAULT_CHUNK_ROWS)
MAX_STEPS = 1000  # an axis's values (sim_core.world.reach.grid_values)
PARTS = ("highest", "last", "completed", "status", "topped")  # a chunk's grids (reach_rows), in order


def cells(job) -> int:
    return job.psi0_steps * job.zeta0_steps


def worst_case(job) -> WorstCase:
    return cells(job) * job.jumps, "psi0_steps x zeta0_steps x jumps"


def row_blocks(job) -> int:
    return -(-job.zeta0_steps // CHUNK_ROWS)


Steps = Annotated[int, Field(ge=1, le=MAX_STEPS, description=f"values on the axis, evenly spaced, in [1, {MAX_STEPS}]")]


class ReachJobCreate(Strict):
    """How high each symmetric schedule of the grid ``psi0_range`` x ``zeta0_range`` climbs the
    stored world ``world_id`` from touchdown 0, in up to ``jumps`` jumps, and how it ends."""

    kind: Literal["reach"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    world_id: WorldRef
    state: StateIn | None = Field(None, description="the body's velocity at touchdown 0; none: the 30:0.9 gait's")
    psi0_range: Annotated[
        list[Psi0Deg], Field(min_length=2, max_length=2, description="[low, high] of the grid's leg angles [deg]")
    ] = [20.0, 40.0]
    psi0_steps: Steps = 21
    zeta0_range: Annotated[
        list[Zeta0], Field(min_length=2, max_length=2, description="[low, high] of the grid's leg lengths [l0]")
    ] = [0.84, 0.96]
    zeta0_steps: Steps = 13
    jumps: Annotated[int, Field(ge=1, le=1_000_000, description="most jumps a cell (a schedule)")] = 40
    foot_y: Annotated[
        float, Field(ge=-100.0, le=100.0, description="touchdown 0's foot height on the left side [l0]")
    ] = 0.0

    @field_validator("psi0_range", "zeta0_range")
    @classmethod
    def _low_below_high(cls, value: list[float]) -> list[float]:
        if not value[0] < value[1]:
            raise ValueError(f"must be [low, high] with low below high, got [{value[0]:g}, {value[1]:g}]")
        return value

    @model_validator(mode="after")
    def _within_limits(self) -> ReachJobCreate:
        if cells(self) > MAX_CELLS:
            raise ValueError(f"psi0_steps x zeta0_steps must be at most {MAX_CELLS:,} cells, got "
                             f"{self.psi0_steps} x {self.zeta0_steps} = {cells(self):,}")  # fmt: skip
        if cells(self) * self.jumps > MAX_CELL_JUMPS:
            raise ValueError(f"psi0_steps x zeta0_steps x jumps must be at most {MAX_CELL_JUMPS:,}, got "
                             f"{cells(self):,} cells x {self.jumps:,} jumps: ask for fewer")  # fmt: skip
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class ReachSpec:
    world_id: int
    world: dict | None = None  # the stored world's §8 JSON in l0, copied when the job was accepted
    model: ModelSpec = field(default_factory=ModelSpec)
    state: StateSpec | None = None
    psi0_range: tuple[float, float] = (20.0, 40.0)
    psi0_steps: int = 21
    zeta0_range: tuple[float, float] = (0.84, 0.96)
    zeta0_steps: int = 13
    jumps: int = 40
    foot_y: float = 0.0
    kind: str = "reach"


def _grid(spec: ReachSpec, context: JobContext) -> tuple:
    """The body's velocity at touchdown 0 and the grid's axes, ``(state, psi0_deg, zeta0s)``."""
    from sim_core.planning.launch import start_velocity
    from sim_core.world.reach import grid_values

    state = start_velocity(context.model) if spec.state is None else (spec.state.xdot, spec.state.ydot)
    psi0_deg = grid_values(*spec.psi0_range, spec.psi0_steps)
    return (float(state[0]), float(state[1])), psi0_deg, grid_values(*spec.zeta0_range, spec.zeta0_steps)


def arguments(spec: ReachSpec, context: JobContext) -> list[tuple]:
    """A chunk per block of zeta0 rows: :func:`~sim_core.world.reach.reach_rows`'s arguments."""
    from sim_core.world.reach import reach_chunks

    state, psi0_deg, zeta0s = _grid(spec, context)
    return reach_chunks(context.model, world_of(spec), psi0_deg, zeta0s, state, spec.jumps, spec.foot_y, CHUNK_ROWS)


def reach_chunk(*arguments) -> dict:
    """One block of rows: its grids as lists of rows."""
    from sim_core.world.reach import reach_rows

    return {name: grid.tolist() for name, grid in zip(PARTS, reach_rows(*arguments), strict=True)}


def combine(spec: ReachSpec, context: JobContext, results: list[dict]) -> dict:
    """``parkour reach --json`` from every block's rows (its ``l0_m``: the robot's leg length)."""
    from sim_core.world.reach import reach_of

    state, psi0_deg, zeta0s = _grid(spec, context)
    rows = [[block[name] for name in PARTS] for block in results]
    reach = reach_of(world_of(spec), state, spec.foot_y, spec.jumps, psi0_deg, zeta0s, rows)
    return reach.to_dict() | {"l0_m": context.robot.leg_length, "world": label_of(spec)}


# typical_fraction: grids of 21x13 to 101x101 cells x 40-400 jumps on four worlds (staircase, narrowing,
# parallel, random seed 4), from the 30:0.9 gait's velocity and from (-1, 0.5), took 0.02-0.25 of their
# worst case at the job worker's rate (climbing worlds the most: few cells end early), their median 0.11;
# the default grid, 0.07 s whatever, is mostly its overhead.
KIND = JobKind(
    "reach", "reach of a grid of leg schedules in a stored world", ReachJobCreate, ReachSpec, worst_case,
    run=None, total=row_blocks, typical_fraction=0.1,
    warm={"world_id": 1, "psi0_steps": 2, "zeta0_steps": 2, "jumps": 5},
    chunked=Chunked(arguments, reach_chunk, combine),
)  # fmt: skip
