"""The mean first-passage time of a gait under noise (``parkour mfpt``), from a Markov chain on the
section. A kind apart from a controller's MFPT (:mod:`backend.jobs.loop_mfpt`): they share no
field but the noise, and a strict body of each refuses the other's fields."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase, gait_not_found_as_parameter_error
from backend.jobs.budget import within_budget
from backend.jobs.specs import ModelSpec, NoiseSpec, StateSpec
from backend.schemas.common import ModelIn, Psi0Deg, RecordRef, StateIn, Strict, Zeta0
from backend.schemas.noise import NoiseIn
from sim_core.model.noise import ASYMMETRY_LIMITS
from sim_core.robustness.mfpt_grid import ChainGrid

# The chain in the job worker: at most this many (velocity node, pitch) pairs a grid, so that the
# worst case (both grids, the finest rule) stays within the work budget.
MFPT_MAX_PAIRS = 600_000
MFPT_MAX_GRID = 60


def mfpt_grid_of(job) -> ChainGrid:
    """The chain's grid of an MFPT job (request body or stored spec)."""
    return ChainGrid(velocity_nodes=job.grid, pitch_spacing=job.pitch_spacing, max_pairs=MFPT_MAX_PAIRS)


def worst_case(job) -> WorstCase:
    drifts = job.noise.pitch_drift_deg > 0.0
    return mfpt_grid_of(job).worst_case_jumps(drifts), "2 grids x (pairs x draws + paths x path jumps)"


class MfptJobCreate(Strict):
    """The mean first-passage time of symmetric controls under noise (``parkour mfpt``), from the
    gait's fixed point (or ``start``), on a grid of ``grid`` velocity nodes and one √2 coarser."""

    kind: Literal["mfpt"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    psi0_deg: Psi0Deg = 30.0
    zeta0: Zeta0 = 0.9
    start: StateIn | None = None
    guess: StateIn | None = None
    noise: NoiseIn = NoiseIn()
    grid: Annotated[
        int, Field(ge=4, le=MFPT_MAX_GRID, description="velocity nodes per axis over where noisy paths go")
    ] = ChainGrid().velocity_nodes
    pitch_spacing: Annotated[
        float, Field(ge=0.25, le=2.0, description="pitch nodes' spacing [standard deviations of the pitch step]")
    ] = ChainGrid().pitch_spacing

    @field_validator("noise")
    @classmethod
    def _symmetric(cls, noise: NoiseIn) -> NoiseIn:
        for field_name in ASYMMETRY_LIMITS:
            if getattr(noise, field_name) != 0.0:
                raise ValueError(
                    f"{field_name} must be 0 for the MFPT chain (an L/R asymmetry needs the wall in the state)"
                )
        return noise

    @model_validator(mode="after")
    def _within_budget(self) -> MfptJobCreate:
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class MfptSpec:
    model: ModelSpec = field(default_factory=ModelSpec)
    psi0_deg: float = 30.0
    zeta0: float = 0.9
    start: StateSpec | None = None
    guess: StateSpec | None = None
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    grid: int = 30
    pitch_spacing: float = 0.5
    kind: str = "mfpt"


def run(spec: MfptSpec, context: JobContext) -> dict:
    """``parkour mfpt --json`` of the job's controls, noise and grid (both grids in-process: the
    chain's two solves are one computation, its progress by chunks of pairs)."""
    from sim_core.model.controls import ControlSchedule, LegControl
    from sim_core.robustness.mfpt import check_chain_inputs, mfpt
    from sim_core.section.gait_search import gait_of

    model, noise = context.model, spec.noise.model()
    check_chain_inputs(model, noise)
    controls = LegControl.from_degrees(spec.psi0_deg, spec.zeta0)
    if spec.start is not None:
        start = (spec.start.xdot, spec.start.ydot)
    else:
        guess = None if spec.guess is None else (spec.guess.xdot, spec.guess.ydot)
        with gait_not_found_as_parameter_error():
            start = gait_of(model, ControlSchedule((controls,)), guess=guess).state
    return mfpt(model, controls, noise, start=start, grid=mfpt_grid_of(spec), progress=context.progress).to_dict()


KIND = JobKind(
    "mfpt",
    "MFPT (mean first-passage time, Markov chain)",
    MfptJobCreate,
    MfptSpec,
    worst_case,
    run,
    typical_fraction=0.0024,
    warm={"grid": 4},
)
