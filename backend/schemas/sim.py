"""The quick simulations a page asks for while a person waits: the map, a sampled path, a gait."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

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
