"""The foothold study (``parkour foothold-study``) as a job: foot placement following a plan
against the best fixed schedule, on one stored world or on random-foothold worlds drawn from
seeds, every method on the same noise draws (docs/worlds.md, "The foothold study").

One world is one chunk (:func:`sim_core.planning.study.study_world`), stored as it finishes: a
restart — after a kill -9 too — computes only the worlds missing, and the result is the one an
uninterrupted job gives (each world's trials depend on the seed alone). The result is ``parkour
foothold-study --json`` of the same worlds and options.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, model_validator

from backend.jobs.base import Chunked, JobContext, JobKind, WorstCase
from backend.jobs.budget import within_budget
from backend.jobs.in_world import (
    PLAN_SEARCH_JUMPS,
    GoalHeightM,
    WorldRef,
    check_goal_in,
    goal_in_l0,
    label_of,
    world_of,
)
from backend.jobs.specs import ModelSpec, NoiseSpec, StateSpec
from backend.schemas.common import ModelIn, RecordRef, StateIn, Strict
from backend.schemas.noise import NoiseIn

MAX_RANDOM = 1000  # random worlds a study (parkour foothold-study --random)
MAX_STUDY_TRIALS = 10_000  # trials a world (sim_core.planning.study.MAX_TRIALS)
REACH_SEARCH_JUMPS = 13 * 9 * 40  # a world's reach search: the planner's grid of legs x REACH_JUMPS


def worlds_in(job) -> int:
    return 1 if job.random_worlds is None else job.random_worlds.count


def worst_case(job) -> WorstCase:
    jumps = worlds_in(job) * (2 * job.trials * job.cap + REACH_SEARCH_JUMPS + PLAN_SEARCH_JUMPS)
    return jumps, f"worlds x (2 methods x trials x cap + {REACH_SEARCH_JUMPS + PLAN_SEARCH_JUMPS} for the searches)"


class RandomWorldsIn(Strict):
    """``count`` random-foothold worlds (:func:`sim_core.world.random_world.random_world`, its
    defaults, the model's width), seeds ``seed0``, ``seed0 + 1``, ..."""

    count: Annotated[int, Field(ge=1, le=MAX_RANDOM, description="random worlds")]
    seed0: Annotated[int, Field(ge=0, lt=2**31, description="the first world's seed")] = 0


class FootholdStudyJobCreate(Strict):
    """Foot placement against the best fixed schedule on the stored world ``world_id`` or on
    ``random_worlds`` (one of the two): ``trials`` noisy climbs a world and method to a foot at
    ``goal_height_m``, from touchdown 0 on the left side at the floor."""

    kind: Literal["foothold-study"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    world_id: WorldRef | None = None
    random_worlds: RandomWorldsIn | None = None
    goal_height_m: GoalHeightM
    trials: Annotated[int, Field(ge=1, le=MAX_STUDY_TRIALS, description="noisy trials a world and method")] = 20
    cap: Annotated[int, Field(ge=1, le=100_000, description="most jumps a trial")] = 200
    seed: Annotated[int, Field(ge=0, lt=2**62, description="trial i of every world and method is seed + i")] = 0
    noise: NoiseIn = NoiseIn()
    state: StateIn | None = Field(None, description="the body's velocity at touchdown 0; none: the 30:0.9 gait's")

    @model_validator(mode="after")
    def _one_source(self) -> FootholdStudyJobCreate:
        if (self.world_id is None) == (self.random_worlds is None):
            raise ValueError("give either world_id (a stored world) or random_worlds, not both and not neither")
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class RandomWorldsSpec:
    count: int
    seed0: int = 0


@dataclass(frozen=True)
class FootholdStudySpec:
    goal_height_m: float
    model: ModelSpec = field(default_factory=ModelSpec)
    world_id: int | None = None
    world: dict | None = None  # the stored world's §8 JSON in l0, copied when the job was accepted
    random_worlds: RandomWorldsSpec | None = None
    trials: int = 20
    cap: int = 200
    seed: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    state: StateSpec | None = None
    kind: str = "foothold-study"


def worlds(spec: FootholdStudySpec, context: JobContext) -> list[tuple[str, object]]:
    """The study's ``(label, world)`` pairs, in order: the stored world, or the random ones as
    ``parkour foothold-study --random`` labels them."""
    from sim_core.world.random_world import random_world

    if spec.random_worlds is None:
        return [(label_of(spec), world_of(spec))]
    first = spec.random_worlds.seed0
    return [(f"random:{seed}", random_world(seed, width=context.model.d_hat))
            for seed in range(first, first + spec.random_worlds.count)]  # fmt: skip


def check(spec: FootholdStudySpec, robot) -> None:
    """The goal within every world (the random ones are drawn here: a few ms each)."""
    context = JobContext(spec.model.params(), robot, chunk_map=None, progress=None)
    for label, world in worlds(spec, context):
        check_goal_in(world, spec, robot, label=label)


def _start(spec: FootholdStudySpec, context: JobContext) -> tuple[float, tuple[float, float], object]:
    """The goal [l0], the body's velocity at touchdown 0 and the noise, as the study runs them."""
    from sim_core.planning.launch import start_velocity

    state = start_velocity(context.model) if spec.state is None else (spec.state.xdot, spec.state.ydot)
    return goal_in_l0(spec, context.robot), (float(state[0]), float(state[1])), spec.noise.model()


def arguments(spec: FootholdStudySpec, context: JobContext) -> list[tuple]:
    """A chunk per world: :func:`sim_core.planning.study.study_world`'s arguments."""
    goal, state, noise = _start(spec, context)
    return [(context.model, label, world, goal, state, 0.0, spec.trials, spec.seed, noise, spec.cap)
            for label, world in worlds(spec, context)]  # fmt: skip


def study_chunk(*arguments) -> dict:
    """One world's outcome, as JSON."""
    from sim_core.planning.study import study_world

    return study_world(*arguments).to_record()


def combine(spec: FootholdStudySpec, context: JobContext, results: list[dict]) -> dict:
    """``parkour foothold-study --json`` from every world's outcome."""
    from sim_core.planning.study import FootholdStudy, WorldOutcome

    goal, state, noise = _start(spec, context)
    outcomes = tuple(WorldOutcome.from_record(record) for record in results)
    return FootholdStudy(goal, spec.trials, spec.seed, noise, outcomes, state).to_dict(context.robot.leg_length)


KIND = JobKind(
    "foothold-study", "foothold study (placement vs the best fixed schedule, in worlds)", FootholdStudyJobCreate,
    FootholdStudySpec, worst_case, run=None, total=worlds_in, typical_fraction=0.05,
    warm={"random_worlds": {"count": 1}, "goal_height_m": 0.3, "trials": 1, "cap": 20},
    chunked=Chunked(arguments, study_chunk, combine), check=check,
)  # fmt: skip
