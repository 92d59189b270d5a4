"""Worlds (docs/model.md §8): the lab's worlds stored by name, posted as the §8 JSON, made from a
named world or drawn at random; runs, robot runs and jobs refer to one by ``world_id``."""

from __future__ import annotations

import datetime
from typing import Annotated, Any

from pydantic import BaseModel, Field, model_validator

from backend.schemas.common import Page, Strict
from sim_core.world.named import NAMED_WORLDS
from sim_core.world.random_world import MAX_HOLDS

WorldName = Annotated[str, Field(min_length=1, max_length=200, description="unique among the stored worlds")]
Preset = Annotated[
    str,
    Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$",
          description="the robot whose leg length converts a world in metres and whose wall distance a named "
          "world is built for (paper, or a stored calibration)"),
]  # fmt: skip
Interval = tuple[float, float]


class RandomWorldIn(Strict):
    """A random-foothold chute (``parkour world random``'s options; sim_core's checks name the field)."""

    seed: Annotated[int, Field(ge=0, le=2**32 - 1)]
    holds: Annotated[int, Field(ge=1, le=MAX_HOLDS)] | None = None
    incline_deg: Interval | None = None
    mu: Interval | None = None
    gap: Interval | None = None
    hold_length: Interval | None = None
    height: Annotated[float, Field(gt=0.0, le=1e3)] | None = None


class WorldCreate(Strict):
    """A world to store as ``name``, from exactly one of: ``world`` (the §8 JSON, in ``l0`` or
    metres), ``named`` (a named world, built for ``preset``'s wall distance) or ``random``."""

    name: WorldName
    world: dict[str, Any] | None = Field(None, description="the world file's JSON (docs/model.md §8)")
    named: str | None = Field(
        None, max_length=64, description=f"one of {', '.join(NAMED_WORLDS)}",
        # The panel's chooser of named worlds reads them here (one registry: sim_core's).
        json_schema_extra={"x-named-worlds": [{"name": name, "description": named.description}
                                              for name, named in NAMED_WORLDS.items()]},
    )  # fmt: skip
    random: RandomWorldIn | None = None
    preset: Preset = "paper"

    @model_validator(mode="after")
    def _one_source(self) -> WorldCreate:
        given = [field for field in ("world", "named", "random") if getattr(self, field) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of world, named or random, got {', '.join(given) or 'none'}")
        return self


class WorldRename(Strict):
    name: WorldName


class WorldOut(BaseModel):
    """A stored world: ``world`` as it was posted (or made), where it came from, who stored it and
    how many runs and jobs use it."""

    id: int
    name: str
    world: dict[str, Any]
    source: str = Field(description='"posted", "named:NAME" or "random:SEED"')
    created_at: datetime.datetime
    created_by: str | None
    runs: int = Field(description="runs (simulated or on the robot) in this world")
    jobs: int = Field(description="jobs in this world")


WorldPage = Page[WorldOut]
