"""The viability kernel and its measure (``parkour viability``). Its result is ``parkour viability
--json``'s figures and grids, with the viable state-action pairs packed as bits (``viable_pairs``:
base64 of ``numpy.packbits`` over the C-order array of shape ``viable_pairs_shape`` = (xdot, ydot,
psi0, zeta0) nodes), so that the panel can show any state's viable actions without a second
request: 120² x 40² pairs are 2.9 MB of bits."""

from __future__ import annotations

import base64
from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.specs import ModelSpec
from backend.schemas.common import ModelIn, RecordRef, Strict
from sim_core.viability.grid import DEFAULT_PSI0_DEG, DEFAULT_ZETA0

# The viability map: one jump a state-action pair; 120² x 40² (23 million pairs, ~3 minutes of
# the job worker) at most, and its result (kernel, measure, viable pairs as bits) stays a few MB.
VIABILITY_MAX_STATES = 120
VIABILITY_MAX_ACTIONS = 40
ViabilityPsi0 = Annotated[float, Field(ge=1.0, le=89.0, description="leg angle [deg]")]
ViabilityZeta0 = Annotated[float, Field(ge=0.05, le=0.999, description="leg length [l0]")]


def worst_case(job) -> WorstCase:
    return job.states**2 * job.actions**2, "states² x actions²"


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
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class ViabilitySpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    states: int = 40
    actions: int = 16
    psi0_low_deg: float = 15.0
    psi0_high_deg: float = 55.0
    zeta0_low: float = 0.7
    zeta0_high: float = 0.98
    kind: str = "viability"


def run(spec: ViabilitySpec, context: JobContext) -> dict:
    """The kernel and measure over the job's grid, and every viable pair as bits."""
    from sim_core.viability.engine import compute_viability
    from sim_core.viability.grid import section_grid
    from sim_core.viability.step_map import section_step_map

    grid = section_grid(
        states=spec.states,
        actions=spec.actions,
        psi0_deg_range=(spec.psi0_low_deg, spec.psi0_high_deg),
        zeta0_range=(spec.zeta0_low, spec.zeta0_high),
    )
    result = compute_viability(section_step_map(context.model), grid, progress=context.progress)
    xdot, ydot = grid.state_axes
    psi0, zeta0 = grid.action_axes
    return {
        **result.to_dict(),
        "state_axes": {"xdot": xdot.tolist(), "ydot": ydot.tolist()},
        "action_axes": {"psi0_deg": np.degrees(psi0).tolist(), "zeta0": zeta0.tolist()},
        "viable_pairs": base64.b64encode(np.packbits(result.viable_pairs.ravel())).decode("ascii"),
        "viable_pairs_shape": list(result.viable_pairs.shape),
    }


KIND = JobKind(
    "viability",
    "viability kernel",
    ViabilityJobCreate,
    ViabilitySpec,
    worst_case,
    run,
    typical_fraction=0.29,
    warm={"states": 4, "actions": 2},
)
