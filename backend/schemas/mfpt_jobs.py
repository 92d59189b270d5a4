"""The mean first-passage time jobs: of a gait under noise, from a Markov chain on the section
(``mfpt``, ``parkour mfpt``), and of a closed-loop controller holding a height, by splitting on
its compiled loop (``loop-mfpt``, ``parkour mfpt --controller``).

Two kinds, not one with an optional controller: they share no field but the noise. The chain's
controls, start, guess and grid mean nothing to a controller, whose law, target, replicas and runs
mean nothing to the chain; a strict body of each refuses the other's fields.
"""

from __future__ import annotations

import enum
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from backend.schemas.common import ModelIn, NominalPsi0Deg, Psi0Deg, RecordRef, StateIn, Strict, TargetHeightM, Zeta0
from backend.schemas.job_budget import LOOP_MFPT_MAX_REPLICA_RUNS, MFPT_MAX_GRID, within_budget
from backend.schemas.noise import NoiseIn
from sim_core.control.laws import KINDS
from sim_core.model.errors import ParameterError
from sim_core.model.noise import ASYMMETRY_LIMITS, SIGMA_LIMITS, NoiseModel
from sim_core.robustness.mfpt_grid import ChainGrid

ControllerKind = enum.StrEnum("ControllerKind", {name.replace("-", "_").upper(): name for name in KINDS})
ControllerKind.__doc__ = "A closed-loop law (sim_core.control.laws.KINDS)."


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
        for field in ASYMMETRY_LIMITS:
            if getattr(noise, field) != 0.0:
                raise ValueError(f"{field} must be 0 for the MFPT chain (an L/R asymmetry needs the wall in the state)")
        return noise

    @model_validator(mode="after")
    def _within_budget(self) -> MfptJobCreate:
        return within_budget(self)


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
        return within_budget(self)
