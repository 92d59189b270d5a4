"""The quick simulations a page asks for while a person waits: the map, a sampled path, a gait —
requests, and the answers the compute worker encodes (documented here; the route forwards the
worker's JSON as it is)."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, Field

from backend.schemas.common import LegIn, ModelIn, StateIn, Strict


class MapIn(Strict):
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    start: StateIn
    jumps: Annotated[int, Field(ge=1, le=1000)] = 1


class TrajectoryIn(Strict):
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    start: StateIn
    jumps: Annotated[int, Field(ge=1, le=50)] = 4
    rate: Annotated[float, Field(gt=0.0, le=500.0, description="samples per sqrt(l0/g)")] = 60.0


class FixedPointIn(Strict):
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    guess: StateIn | None = None


class FailureOut(BaseModel):
    code: str = Field(description="the failure's name (slip, wall_miss, ...)")
    jump: int = Field(description="the jump it ended, from 0")


class MapOut(BaseModel):
    """The orbit of the jump-to-jump map (``parkour map --json``), nondimensional."""

    states: list[list[float | None]] = Field(description="section states (xdot, ydot), the start first")
    rises: list[float | None] = Field(description="height gained by each jump [l0]")
    failure: FailureOut | None


class PathScales(BaseModel):
    preset: str
    l0_m: float
    time_s: float
    speed_m_per_s: float


class TrajectoryOut(BaseModel):
    """A sampled path in wall coordinates, column by column, with what turns it into SI units."""

    units: str
    columns: dict[str, list[float | int | None]]
    touchdown_times: list[float | None]
    failure: FailureOut | None
    walls_x: list[float] = Field(description="the walls' x [l0], the centre line at 0")
    si: PathScales


class FixedPointOut(BaseModel):
    """A gait (``parkour fixed-point --json``): its section state, period, eigenvalues and orbit."""

    state: list[float | None]
    period: int
    eigenvalues: list[list[float]] = Field(description="(real, imaginary) pairs")
    max_abs_eigenvalue: float
    stable: bool
    climb_per_period: float | None
    residual: float | None
    motion: str | None
    orbit: list[list[float | None]]
