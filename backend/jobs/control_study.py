"""The closed-loop benchmark (``parkour control-study``): each controller climbing to a height on
the same noise draws (docs/analyses.md, "Controllers")."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.specs import ModelSpec, NoiseSpec
from backend.schemas.common import MAX_TRIALS, ModelIn, NominalPsi0Deg, RecordRef, Strict, TargetHeightM, Zeta0
from backend.schemas.noise import NoiseIn
from sim_core.control.registry import NAMES


def worst_case(job) -> WorstCase:
    return len(job.controllers) * job.seeds * job.jumps, "controllers x seeds x jumps"


class ControlStudyJobCreate(Strict):
    """The closed-loop benchmark (``parkour control-study``): each controller climbing to
    ``target_m`` on the same noise draws, ``seeds`` trials of ``jumps`` jumps each."""

    kind: Literal["control-study"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controllers: Annotated[
        list[str], Field(min_length=1, max_length=8, description=f"names, each once, of: {', '.join(NAMES)}")
    ] = list(NAMES)
    target_m: TargetHeightM = 0.55
    psi0_deg: NominalPsi0Deg = 35.0
    start_zeta0: Zeta0 = 0.9
    jumps: Annotated[int, Field(ge=1, le=100_000)] = 400
    seeds: Annotated[int, Field(ge=1, le=MAX_TRIALS)] = 200
    seed0: Annotated[int, Field(ge=0, le=2**32 - MAX_TRIALS)] = 0
    noise: NoiseIn = NoiseIn()

    @field_validator("controllers")
    @classmethod
    def _known(cls, names: list[str]) -> list[str]:
        unknown = [name for name in names if name not in NAMES]
        if unknown:
            raise ValueError(f"must be among {', '.join(NAMES)}, got {unknown[0]!r}")
        if len(set(names)) != len(names):
            raise ValueError(f"names a controller twice: {', '.join(names)}")
        return names

    @model_validator(mode="after")
    def _within_budget(self) -> ControlStudyJobCreate:
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class ControlStudySpec:
    # The default of version 1's day, not the registry's: a stored spec keeps what it was accepted under.
    controllers: tuple[str, ...] = ("pid", "pid-pitch", "lqr", "deadbeat")
    model: ModelSpec = field(default_factory=ModelSpec)
    target_m: float = 0.55
    psi0_deg: float = 35.0
    start_zeta0: float = 0.9
    jumps: int = 400
    seeds: int = 200
    seed0: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    kind: str = "control-study"


def run(spec: ControlStudySpec, context: JobContext) -> dict:
    """The benchmark's JSON (``parkour control-study --json``) and what the panel plots of it."""
    from experiments.control_study import Config
    from experiments.control_study import run as run_study

    config = Config(controllers=tuple(spec.controllers), target_m=spec.target_m, psi0_deg=spec.psi0_deg,
                    start_zeta0=spec.start_zeta0, jumps=spec.jumps, seeds=spec.seeds, seed0=spec.seed0,
                    noise=spec.noise.model())  # fmt: skip
    result = run_study(context.model, context.robot.leg_length, config, chunk_map=context.chunk_map,
                       progress=context.progress)  # fmt: skip
    return {**result.to_dict(), "plots": result.plots()}


KIND = JobKind("control-study", "controllers (closed-loop benchmark)", ControlStudyJobCreate, ControlStudySpec,
               worst_case, run, typical_fraction=4.5, warm={"seeds": 1, "jumps": 2})  # fmt: skip
