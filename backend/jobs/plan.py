"""A plan as a job (``parkour plan``): the most robust way up a stored world to a goal height,
foothold by foothold, and optionally how often the placement law following it (with replanning)
gets there under the noise, by plain Monte-Carlo attempts (docs/worlds.md). Its result is ``parkour
plan --json`` — with ``reaches_goal`` false and the highest foot where no plan reaches the goal
(the command refuses instead), the goal in leg lengths (``goal_l0``, the targets' unit) and the
leg length (``leg_length_m``) — and, with ``attempts``, ``"monte_carlo"`` as the command's
``--mfpt --monte-carlo`` gives it; with ``importance_sampling``, ``"importance_sampling"`` as its
``--importance-sampling`` gives it (the estimate where failures are too rare for as many plain
attempts: docs/worlds.md). (The splitting estimate stays the command's: docs/worlds.md says why it
goes extinct where failures are rare.)"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

from pydantic import Field, model_validator

from backend.jobs.base import JobContext, JobKind, WorstCase
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

MAX_ATTEMPTS = 100_000
# sim_core.planning.plan_importance's, repeated here so that the API loads no kernels (a test holds them equal)
DRAW_KINDS = ("psi0", "zeta0", "velocity", "pitch")  # sim_core.model.noise_rules.TALLY_KINDS
SCALE_LIMITS = (1.0, 5.0)
DrawKind = Literal["psi0", "zeta0", "velocity", "pitch"]


def worst_case(job) -> WorstCase:
    sampled = 0 if job.importance_sampling is None else job.importance_sampling.trials
    return (
        PLAN_SEARCH_JUMPS + (job.attempts + sampled) * job.cap,
        f"{PLAN_SEARCH_JUMPS} (the search) + (attempts + importance_sampling.trials) x cap",
    )


class ImportanceIn(Strict):
    """Importance-sampled climbs of the plan: each draw of the ``draws`` kinds widened x ``scale``
    (at touchdown 0 alone with ``first_leg``), each climb weighted by its draws' likelihood ratio:
    the failure chance where it is too rare for as many plain attempts (docs/worlds.md; at low noise
    touchdown 0's draws decide the failures: first_leg with scale 3)."""

    trials: Annotated[int, Field(ge=2, le=MAX_ATTEMPTS, description="importance-sampled climbs")]
    scale: Annotated[float, Field(ge=SCALE_LIMITS[0], le=SCALE_LIMITS[1], description="the draws' widening")] = 1.5
    draws: Annotated[list[DrawKind], Field(min_length=1, max_length=4, description="the kinds of draw widened")] = list(
        DRAW_KINDS
    )
    first_leg: bool = Field(False, description="widen touchdown 0's draws only")


class PlanJobCreate(Strict):
    """The most robust plan up the stored world ``world_id`` to a foot at ``goal_height_m``, from
    touchdown 0 on the left side at the floor; with ``attempts``, that many noisy climbs of it by
    the placement law (at most ``replans`` replans each, ``cap`` jumps), counted."""

    kind: Literal["plan"]
    experiment_id: RecordRef | None = None
    model: ModelIn = ModelIn()
    world_id: WorldRef
    goal_height_m: GoalHeightM
    seed: Annotated[int, Field(ge=0, lt=2**31, description="the search's draws; attempt i is seed + i")] = 0
    noise: NoiseIn = NoiseIn()
    state: StateIn | None = Field(None, description="the body's velocity at touchdown 0; none: the 30:0.9 gait's")
    launch_gait: bool = Field(
        False,
        description="the body arrives at touchdown 0 with its own first leg's gait's velocity, as a robot "
        "launched on that leg does (for a live run that follows the plan); not with state",
    )
    attempts: Annotated[int, Field(ge=0, le=MAX_ATTEMPTS, description="noisy climbs of the plan; 0: none")] = 0
    replans: Annotated[int, Field(ge=0, le=10, description="replans an attempt may make")] = 3
    cap: Annotated[int, Field(ge=1, le=10_000, description="most jumps an attempt")] = 200
    importance_sampling: ImportanceIn | None = None

    @model_validator(mode="after")
    def _within_budget(self) -> PlanJobCreate:
        if self.launch_gait and self.state is not None:
            raise ValueError("give state or launch_gait, not both")
        return within_budget(self, worst_case(self))


@dataclass(frozen=True)
class ImportanceSpec:
    trials: int
    scale: float = 1.5
    draws: tuple[str, ...] | list[str] = DRAW_KINDS
    first_leg: bool = False


@dataclass(frozen=True)
class PlanSpec:
    world_id: int
    goal_height_m: float
    world: dict | None = None  # the stored world's §8 JSON in l0, copied when the job was accepted
    model: ModelSpec = field(default_factory=ModelSpec)
    seed: int = 0
    noise: NoiseSpec = field(default_factory=NoiseSpec)
    state: StateSpec | None = None
    launch_gait: bool = False
    attempts: int = 0
    replans: int = 3
    cap: int = 200
    importance_sampling: ImportanceSpec | None = None
    kind: str = "plan"


def check(spec: PlanSpec, robot) -> None:
    """The goal above the start and within the world (the planner says how high it got otherwise)."""
    check_goal_in(world_of(spec), spec, robot, label=label_of(spec), footholds=False)


def run(spec: PlanSpec, context: JobContext) -> dict:
    from sim_core.planning.launch import start_velocity
    from sim_core.planning.plan_importance import plan_importance
    from sim_core.planning.plan_splitting import PlanSplitting, plan_monte_carlo
    from sim_core.planning.planner import plan_climb

    world, goal, noise = world_of(spec), goal_in_l0(spec, context.robot), spec.noise.model()
    state = start_velocity(context.model) if spec.state is None else (spec.state.xdot, spec.state.ydot)
    plan = plan_climb(context.model, world, goal, state, noise=noise, seed=spec.seed, launch_gait=spec.launch_gait)
    sampled = spec.importance_sampling
    parts = 1 + (bool(spec.attempts) + (sampled is not None) if plan.reaches_goal else 0)
    context.progress(1, parts)
    state = plan.steps[0].velocity if spec.launch_gait and plan.steps else state
    document = plan.to_dict(context.robot.leg_length) | {
        "world": label_of(spec),
        "state": [float(v) for v in state],
        "goal_l0": goal,
        "leg_length_m": context.robot.leg_length,
    }
    options = PlanSplitting(seed=spec.seed, cap=spec.cap, max_replans=spec.replans)
    done = 1
    if spec.attempts and plan.reaches_goal:
        checked = plan_monte_carlo(context.model, world, plan, goal, noise, options, spec.attempts, spec.seed)
        document["monte_carlo"] = checked.to_dict()
        done += 1
        context.progress(done, parts)
    if sampled is not None and plan.reaches_goal:
        widened = {"scaled": tuple(sampled.draws), "first_leg_only": sampled.first_leg}
        first = spec.seed + spec.attempts  # seeds no attempt used: the two estimates independent
        weighed = plan_importance(context.model, world, plan, goal, noise, options, sampled.trials, first,
                                  sampled.scale, **widened)  # fmt: skip
        document["importance_sampling"] = weighed.to_dict()
        context.progress(done + 1, parts)
    return document


KIND = JobKind(
    "plan", "plan a climb up a stored world", PlanJobCreate, PlanSpec, worst_case, run, typical_fraction=0.01,
    warm={"world_id": 1, "goal_height_m": 0.3}, check=check,
)  # fmt: skip
