"""A closed-loop controller's mean first-passage time (``parkour mfpt --controller``): the law
holding a height, by splitting on its compiled loop. Its progress is reported per splitting run;
its draws all come from the job's seed, so a restart recomputes the same result."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.specs import ModelSpec, NoiseSpec
from backend.schemas.common import ControllerKind, ModelIn, NominalPsi0Deg, RecordRef, Strict, TargetHeightM, Zeta0
from backend.schemas.noise import NoiseIn
from sim_core.model.errors import ParameterError
from sim_core.model.noise import SIGMA_LIMITS, NoiseModel

# A controller's MFPT by splitting (sim_core.robustness.splitting): its work is AMS runs of replicas, each
# replica's excursions ended home, at a failure or at SplittingOptions' excursion_limit (20,000
# jumps). One replica's share of a run is counted at that limit, the long run and climbs that
# measure the holding state before them at theirs (pilot_jumps + climbs x excursion_limit, the
# defaults): far above what they take (0.8-24 ms a replica-run measured, pid to deadbeat at velocity
# noise 0.05, 2 cores: 100-3,300 jumps at the job rate) but a rarer failure takes more levels. So
# replicas x runs is bounded, and the worst case stays within the work budget.
LOOP_MFPT_REPLICA_JUMPS = 20_000
LOOP_MFPT_SETUP_JUMPS = 20_000 + 200 * 20_000
LOOP_MFPT_MAX_REPLICA_RUNS = 20_000


def worst_case(job) -> WorstCase:
    jumps = job.replicas * job.runs * LOOP_MFPT_REPLICA_JUMPS + LOOP_MFPT_SETUP_JUMPS
    return jumps, f"replicas x runs x {LOOP_MFPT_REPLICA_JUMPS} + {LOOP_MFPT_SETUP_JUMPS} for the holding state"


def _metastable(noise: NoiseModel) -> None:
    """sim_core's refusal of noise splitting cannot take (:func:`sim_core.robustness.splitting.check_metastable`),
    as a ValueError in its words. Imported only to refuse: the kernels' module loads in seconds."""
    if noise.pitch_drift_deg != 0.0 or noise.velocity == noise.psi0_deg == noise.zeta0 == 0.0:
        from sim_core.robustness.splitting import check_metastable

        try:
            check_metastable(noise)
        except ParameterError as error:
            raise ValueError(error.message) from None


class LoopNoiseIn(NoiseIn):
    """A controller's noise: as the other jobs take it, but no pitch drift (its default here is 0)."""

    pitch_drift_deg: Annotated[
        float,
        Field(ge=0.0, lt=SIGMA_LIMITS["pitch_drift_deg"], description="must be 0: with it a loop is not metastable"),
    ] = 0.0

    @field_validator("pitch_drift_deg")
    @classmethod
    def _no_drift(cls, value: float) -> float:
        _metastable(NoiseModel(pitch_drift_deg=value))
        return value

    @model_validator(mode="after")
    def _some_noise(self) -> LoopNoiseIn:
        _metastable(NoiseModel(**self.model_dump()))
        return self


class LoopMfptJobCreate(Strict):
    """A closed-loop controller's mean first-passage time (``parkour mfpt --controller``): the law
    holding ``target_m`` after the control study's climb, by ``runs`` independent splitting runs of
    ``replicas`` each, the draws fixed by ``seed``."""

    kind: Literal["loop-mfpt"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    controller: ControllerKind = ControllerKind.LQR
    target_m: TargetHeightM = 0.55
    psi0_deg: NominalPsi0Deg = 35.0
    start_zeta0: Zeta0 = 0.9
    noise: LoopNoiseIn = LoopNoiseIn()
    replicas: Annotated[int, Field(ge=2, le=1000, description="replicas per splitting run")] = 100
    runs: Annotated[int, Field(ge=2, le=256, description="independent splitting runs, for the interval")] = 64
    seed: Annotated[int, Field(ge=0, lt=2**32, description="the seed of every draw")] = 0

    @model_validator(mode="after")
    def _within_budget(self) -> LoopMfptJobCreate:
        if self.replicas * self.runs > LOOP_MFPT_MAX_REPLICA_RUNS:
            raise ValueError(
                f"replicas x runs must be at most {LOOP_MFPT_MAX_REPLICA_RUNS} (the splitting's work bound, within "
                f"the job budget), got {self.replicas} x {self.runs} = {self.replicas * self.runs}; ask for fewer"
            )
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class LoopMfptSpec:
    controller: str = "lqr"
    model: ModelSpec = field(default_factory=ModelSpec)
    target_m: float = 0.55
    psi0_deg: float = 35.0
    start_zeta0: float = 0.9
    noise: NoiseSpec = field(default_factory=lambda: NoiseSpec(pitch_drift_deg=0.0))
    replicas: int = 100
    runs: int = 64
    seed: int = 0
    kind: str = "loop-mfpt"


def run(spec: LoopMfptSpec, context: JobContext) -> dict:
    """``parkour mfpt --controller --json`` of the job's law, target, climb, noise and splitting."""
    from experiments.loop_mfpt import Config
    from experiments.loop_mfpt import run as run_splitting
    from sim_core.robustness.splitting import SplittingOptions

    options = SplittingOptions(replicas=spec.replicas, runs=spec.runs, seed=spec.seed)
    config = Config(controller=spec.controller, target_m=spec.target_m, psi0_deg=spec.psi0_deg,
                    start_zeta0=spec.start_zeta0, noise=spec.noise.model(), options=options)  # fmt: skip
    return run_splitting(context.model, context.robot.leg_length, config, progress=context.progress)


KIND = JobKind(
    "loop-mfpt",
    "MFPT of a controller (splitting)",
    LoopMfptJobCreate,
    LoopMfptSpec,
    worst_case,
    run,
    typical_fraction=0.003,
    warm={"controller": "pid", "replicas": 2, "runs": 2, "noise": {"velocity": 0.05}},
)
