"""Mean Jumps To Failure in a stored world as a job: ``trials`` noisy climbs of a fixed leg
schedule (its legs in turn) from touchdown 0 on the left side at the floor, each to a failure (the
floor included), the ``cap`` or — with ``goal_height_m`` — a foot at the goal
(:func:`sim_core.robustness.world_trials.run_world_trials`; trial i is seed ``seed + i``).

Chunked by blocks of :data:`BLOCK` trials, each stored as it finishes: a restart computes only the
blocks missing, and the result is the uninterrupted job's. The result: the trials' jumps and
outcomes one by one, their mean and sample standard deviation, and the outcomes counted.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, model_validator

from backend.jobs.base import Chunked, JobContext, JobKind, WorstCase, schedule_of
from backend.jobs.budget import within_budget
from backend.jobs.in_world import GoalHeightM, WorldRef, check_goal_in, goal_in_l0, label_of, world_of
from backend.jobs.specs import LegSpec, ModelSpec, NoiseSpec, StateSpec
from backend.schemas.common import MAX_TRIALS, LegIn, ModelIn, RecordRef, StateIn, Strict
from backend.schemas.noise import NoiseIn

BLOCK = 256  # trials a chunk: a commit each
REACHED, CAPPED = "reached", "capped"


def worst_case(job) -> WorstCase:
    return job.trials * job.cap, "trials x cap"


def blocks(job) -> int:
    return -(-job.trials // BLOCK)


class WorldMjtfJobCreate(Strict):
    """``trials`` noisy climbs of ``controls`` (the legs in turn, from touchdown 0) in the stored
    world ``world_id``, each to a failure, the ``cap`` or a foot at ``goal_height_m`` (none: no goal)."""

    kind: Literal["world-mjtf"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    world_id: WorldRef
    controls: Annotated[list[LegIn], Field(min_length=1, max_length=64, description="the legs, in turn")]
    goal_height_m: GoalHeightM | None = None
    trials: Annotated[int, Field(ge=1, le=MAX_TRIALS)] = 100
    cap: Annotated[int, Field(ge=1, le=100_000, description="most jumps a trial")] = 1000
    seed: Annotated[int, Field(ge=0, lt=2**62, description="trial i is seed + i")] = 0
    noise: NoiseIn = NoiseIn()
    state: StateIn | None = Field(None, description="the body's velocity at touchdown 0; none: the 30:0.9 gait's")

    @model_validator(mode="after")
    def _within_budget(self) -> WorldMjtfJobCreate:
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class WorldMjtfSpec:
    world_id: int
    controls: tuple[LegSpec, ...]
    world: dict | None = None  # the stored world's §8 JSON in l0, copied when the job was accepted
    model: ModelSpec = field(default_factory=ModelSpec)
    goal_height_m: float | None = None
    trials: int = 100
    cap: int = 1000
    seed: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    state: StateSpec | None = None
    kind: str = "world-mjtf"


def check(spec: WorldMjtfSpec, robot) -> None:
    if spec.goal_height_m is not None:
        check_goal_in(world_of(spec), spec, robot, label=label_of(spec))


def arguments(spec: WorldMjtfSpec, context: JobContext) -> list[tuple]:
    """A chunk per block of trials: :func:`~sim_core.robustness.world_trials.run_world_trials`'s arguments."""
    import math

    import numpy as np

    from sim_core.planning.launch import start_velocity

    state = start_velocity(context.model) if spec.state is None else (spec.state.xdot, spec.state.ydot)
    goal = math.inf if spec.goal_height_m is None else goal_in_l0(spec, context.robot)
    schedule, world, noise = schedule_of(spec.controls).as_array(), world_of(spec), spec.noise.model()
    seeds = spec.seed + np.arange(spec.trials, dtype=np.int64)
    return [(context.model, schedule, tuple(map(float, state)), noise, seeds[start:start + BLOCK], spec.cap, world,
             0.0, goal) for start in range(0, spec.trials, BLOCK)]  # fmt: skip


def trials_chunk(*arguments) -> dict:
    """One block's trials: their jumps and outcomes."""
    from sim_core.model.failures import OK, Failure
    from sim_core.robustness.world_trials import REACHED as REACHED_STATUS
    from sim_core.robustness.world_trials import run_world_trials

    jumps, status = run_world_trials(*arguments)
    said = {REACHED_STATUS: REACHED, OK: CAPPED}
    return {"jumps": [int(n) for n in jumps], "outcomes": [said.get(int(s)) or Failure(int(s)).code for s in status]}


def combine(spec: WorldMjtfSpec, context: JobContext, results: list[dict]) -> dict:
    from collections import Counter

    from sim_core.robustness.mjtf_plan import jump_statistics

    jumps = [n for block in results for n in block["jumps"]]
    outcomes = [outcome for block in results for outcome in block["outcomes"]]
    mean, std = jump_statistics(len(jumps), sum(jumps), sum(n * n for n in jumps))
    return {"world": label_of(spec), "trials": len(jumps), "mean_jumps": mean, "std_jumps": std,
            "outcomes": dict(sorted(Counter(outcomes).items())), "jumps": jumps, "trial_outcomes": outcomes,
            "goal_height_m": spec.goal_height_m, "seed": spec.seed}  # fmt: skip


KIND = JobKind(
    "world-mjtf", "Mean Jumps To Failure in a stored world", WorldMjtfJobCreate, WorldMjtfSpec, worst_case,
    run=None, total=blocks, typical_fraction=0.1,
    warm={"world_id": 1, "controls": [{"psi0_deg": 30.0, "zeta0": 0.9}], "trials": 2, "cap": 20},
    chunked=Chunked(arguments, trials_chunk, combine), check=check,
)  # fmt: skip
