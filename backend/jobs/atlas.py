"""The gait atlas (``parkour atlas``, symmetric): where stable gaits live over a grid of leg angle
(rows) x leg length (columns), each cell's orbits from four starts let settle, their cycles
refined into gaits (:func:`sim_core.section.atlas.gait_atlas`). Its result is ``parkour atlas
--json``: per cell the most stable gait's period, climb per jump and max |λ|, and every gait found."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.gaits import GAIT_SEARCH_JUMPS
from backend.jobs.specs import ModelSpec
from backend.schemas.common import ModelIn, Psi0Deg, RecordRef, Strict, Zeta0
from sim_core.section.atlas_plan import DEFAULT_STARTS, MAX_PERIOD, TRANSIENT_JUMPS

GridSide = Annotated[int, Field(ge=2, le=200, description="cells along this axis")]


def worst_case(job) -> WorstCase:
    orbit = 2 * MAX_PERIOD + GAIT_SEARCH_JUMPS  # after settling: find the cycle, refine it into a gait
    starts = len(DEFAULT_STARTS)
    jumps = job.rows * job.columns * starts * (job.transient + orbit)
    return jumps, f"rows x columns x {starts} x (transient + {orbit})"


class AtlasJobCreate(Strict):
    """The symmetric gait atlas: ``rows`` leg angles from ``psi0_low_deg`` to ``psi0_high_deg`` x
    ``columns`` leg lengths from ``zeta0_low`` to ``zeta0_high``, each orbit let settle ``transient`` jumps."""

    kind: Literal["atlas"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    psi0_low_deg: Psi0Deg = 15.0
    psi0_high_deg: Psi0Deg = 45.0
    zeta0_low: Zeta0 = 0.80
    zeta0_high: Zeta0 = 0.98
    rows: GridSide = 13
    columns: GridSide = 19
    transient: Annotated[int, Field(ge=1, le=10_000, description="jumps each orbit settles [jumps]")] = TRANSIENT_JUMPS

    @model_validator(mode="after")
    def _ordered(self) -> AtlasJobCreate:
        for low, high in (("psi0_low_deg", "psi0_high_deg"), ("zeta0_low", "zeta0_high")):
            if not getattr(self, low) < getattr(self, high):
                raise ValueError(f"{low} must be below {high}")
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class AtlasSpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_low_deg: float = 15.0
    psi0_high_deg: float = 45.0
    zeta0_low: float = 0.80
    zeta0_high: float = 0.98
    rows: int = 13
    columns: int = 19
    transient: int = TRANSIENT_JUMPS
    kind: str = "atlas"


def run(spec: AtlasSpec, context: JobContext) -> dict:
    """``parkour atlas --json`` over the job's grid, its orbits chunked through the chunk map."""
    import numpy as np

    from sim_core.model.controls import ControlSchedule
    from sim_core.section.atlas import gait_atlas

    rows = np.linspace(spec.psi0_low_deg, spec.psi0_high_deg, spec.rows)
    columns = np.linspace(spec.zeta0_low, spec.zeta0_high, spec.columns)
    schedules = [ControlSchedule.from_degrees([(psi0, zeta0)]) for psi0 in rows for zeta0 in columns]
    labels = {"row_label": "psi0 [deg]", "column_label": "zeta0 [l0]"}
    atlas = gait_atlas(context.model, schedules, rows, columns, **labels, transient_jumps=spec.transient,
                       chunk_map=context.chunk_map, progress=context.progress)  # fmt: skip
    return atlas.to_dict()


KIND = JobKind(
    "atlas",
    "gait atlas (stable gaits over psi0 x zeta0)",
    AtlasJobCreate,
    AtlasSpec,
    worst_case,
    run,
    typical_fraction=0.047,
    warm={"rows": 2, "columns": 2, "transient": 10},
)
