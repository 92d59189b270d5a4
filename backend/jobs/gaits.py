"""A gait search (``parkour gaits``): the distinct gaits of one control schedule, from a grid of guesses."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field

from backend.jobs.base import JobContext, JobKind, WorstCase, schedule_of
from backend.jobs.specs import LegSpec, ModelSpec
from backend.schemas.common import LegIn, ModelIn, RecordRef, Strict

GAIT_SEARCH_JUMPS = 1000  # a gait search's work per guess, at most (Levenberg–Marquardt's map evaluations)


def worst_case(job) -> WorstCase:
    return job.grid**2 * GAIT_SEARCH_JUMPS, f"grid² x {GAIT_SEARCH_JUMPS}"


class GaitSearchJobCreate(Strict):
    """Distinct gaits of one control schedule, from a grid of guesses."""

    kind: Literal["gaits"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=16)]
    period: Annotated[int, Field(ge=1, le=16)] | None = None
    grid: Annotated[int, Field(ge=1, le=20)] = 6


@dataclass(frozen=True)
class GaitSearchSpec:
    controls: tuple[LegSpec, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    period: int | None = None
    grid: int = 6
    kind: str = "gaits"


def run(spec: GaitSearchSpec, context: JobContext) -> dict:
    """The gaits found, each as ``parkour gaits --json`` gives it."""
    from sim_core.section.gait_search import search_gaits

    schedule = schedule_of(spec.controls)
    gaits = search_gaits(context.model, schedule, spec.period or len(schedule), grid=(spec.grid, spec.grid))
    context.progress(1, 1)
    return {"gaits": [gait.to_dict() for gait in gaits]}


KIND = JobKind(
    "gaits",
    "gait search",
    GaitSearchJobCreate,
    GaitSearchSpec,
    worst_case,
    run,
    typical_fraction=0.14,
    warm={"controls": [{"psi0_deg": 30.0, "zeta0": 0.9}], "grid": 1},
)
