"""The foothold study: on many worlds, how often each method climbs to a goal height under the
robot's noise, every method on the same draws (docs/worlds.md, "The foothold study").

Two methods, per world:

- ``open-loop``: the best fixed schedule a reach search finds — every symmetric leg of the
  planner's grid (psi0 15–45° by 2.5°, zeta0 0.80–0.96 by 0.02) climbed without noise for up to
  :data:`REACH_JUMPS` jumps (:func:`sim_core.world.reach.reach_rows`), the one whose foot got
  highest — then climbed under noise (:func:`sim_core.robustness.world_trials.run_world_trials`).
- ``placement``: the most robust plan (:func:`sim_core.planning.planner.plan_climb`) followed by
  the foot-placement law with replanning (:func:`sim_core.planning.follow.follow_plan`); where no
  plan reaches the goal its trials are not run and count as ``no_plan``.

Trial ``i`` of every world and method is seed ``seed + i``: the same draws, in the same order.
A trial ends at the goal (a foot at or above it), at a failure (the floor included) or at
``cap`` jumps (``capped``). One world is one chunk (:mod:`sim_core.chunks`: in process or on a
Dask cluster; the outcome does not depend on which).
"""

from __future__ import annotations

import math
import statistics
import time
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.control.laws.placement import PlacementSettings
from sim_core.model.errors import ParameterError
from sim_core.model.failures import OK, Failure
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_section_state
from sim_core.model.validation import check_range
from sim_core.planning.follow import follow_plan, law_us_per_jump
from sim_core.planning.goals import check_goal
from sim_core.planning.launch import start_velocity
from sim_core.planning.planner import PSI0_DEG, ZETA0, plan_climb
from sim_core.robustness.world_trials import REACHED, run_world_trials
from sim_core.world.geometry import pack
from sim_core.world.reach import reach_rows
from sim_core.world.world import World

METHODS = ("open-loop", "placement")
REACH_JUMPS = 40  # the reach search's jumps per schedule
MAX_WORLDS, MAX_TRIALS = 1000, 10_000  # worlds a study, trials a world
CAPPED, NO_PLAN = "capped", "no_plan"


@dataclass(frozen=True)
class WorldOutcome:
    """One world's trials: per method, how many reached the goal, the failures by code, the jumps
    done (summed over the trials run), the trials run, and the planning's seconds; the law's CPU
    time per jump [µs] (None without a plan)."""

    world: str
    plan_exists: bool
    trials: int
    reached: dict[str, int]
    failures: dict[str, dict[str, int]]
    jumps: dict[str, int]
    run: dict[str, int]
    plan_seconds: dict[str, float]
    law_us: float | None
    replans: int = 0
    schedule: tuple[float, float] = (math.nan, math.nan)  # open-loop's leg (psi0 [deg], zeta0)

    def to_record(self) -> dict:
        """Every field as JSON (a job stores each world's outcome as it finishes); :meth:`from_record`
        reads it back to an equal outcome."""
        return {name: (list(value) if isinstance(value, tuple) else value) for name, value in vars(self).items()}

    @classmethod
    def from_record(cls, record: dict) -> WorldOutcome:
        return cls(**{**record, "schedule": tuple(record["schedule"])})

    def to_dict(self) -> dict:
        """The world's row of ``parkour foothold-study --json``."""
        return {"world": self.world, "plan_exists": self.plan_exists, "trials": self.trials,
                "reached": dict(self.reached)}  # fmt: skip


@dataclass(frozen=True)
class FootholdStudy:
    """Every world's outcome, in the order asked, and what they were asked with."""

    goal: float  # [l0]
    trials: int
    seed: int
    noise: NoiseModel
    worlds: tuple[WorldOutcome, ...] = field(default_factory=tuple)
    state: tuple[float, float] = (math.nan, math.nan)  # the body's velocity at touchdown 0 [sqrt(g l0)]

    def method(self, name: str) -> dict:
        """One method's totals: reached, trials, failures_by_code, mean_jumps (over the trials
        run), plan_seconds_median (over the worlds), law_us_per_jump (the median world's; 0 for
        a fixed schedule, which computes nothing a jump)."""
        failures: Counter = Counter()
        for outcome in self.worlds:
            failures.update(outcome.failures[name])
        run = sum(outcome.run[name] for outcome in self.worlds)
        laws = [outcome.law_us for outcome in self.worlds if outcome.law_us is not None]
        law_us = 0.0 if name == "open-loop" else (statistics.median(laws) if laws else None)
        return {
            "reached": sum(outcome.reached[name] for outcome in self.worlds),
            "trials": sum(outcome.trials for outcome in self.worlds),
            "failures_by_code": dict(sorted(failures.items())),
            "mean_jumps": sum(outcome.jumps[name] for outcome in self.worlds) / run if run else None,
            "plan_seconds_median": statistics.median(outcome.plan_seconds[name] for outcome in self.worlds),
            "law_us_per_jump": law_us,
        }

    def to_dict(self, metres: float) -> dict:
        """The ``parkour foothold-study --json`` contract (heights in metres, l0 = ``metres``)."""
        placement = self.method("placement")
        run = sum(outcome.run["placement"] for outcome in self.worlds)
        placement["replans_per_trial"] = sum(o.replans for o in self.worlds) / run if run else None
        return {
            "methods": {"open-loop": self.method("open-loop"), "placement": placement},
            "worlds": [outcome.to_dict() for outcome in self.worlds],
            "goal_height_m": self.goal * metres,
            "trials_per_world": self.trials,
            "seed": self.seed,
            "state": list(self.state),
            "noise": self.noise.to_dict(),
        }


def study_world(model, label, world, goal, state, foot_y, trials, seed, noise, cap) -> WorldOutcome:
    """One chunk: ``world``'s trials of both methods (see the module)."""
    seeds = seed + np.arange(trials, dtype=np.int64)
    started = time.perf_counter()
    highest, *_ = reach_rows(model, world, np.radians(PSI0_DEG), ZETA0, state, REACH_JUMPS, foot_y)
    row, column = divmod(int(np.argmax(highest)), PSI0_DEG.size)
    schedule = np.array([[math.radians(PSI0_DEG[column]), ZETA0[row]]])
    reach_seconds = time.perf_counter() - started
    jumps, status = run_world_trials(model, schedule, state, noise, seeds, cap, world, foot_y, goal)
    open_failures = Counter(_code(int(code)) for code in status if code != REACHED)
    plan = plan_climb(model, world, goal, state, foot_y=foot_y, noise=noise, seed=seed)
    reached = {"open-loop": int(np.count_nonzero(status == REACHED))}
    failures = {"open-loop": dict(open_failures)}
    done = {"open-loop": int(jumps.sum())}
    run, law_us, replans = {"open-loop": trials}, None, 0
    if plan.reaches_goal:
        sides, settings = pack(world, model.mu), PlacementSettings()
        outcomes = [follow_plan(model, world, plan, goal, noise, int(s), cap=cap, sides=sides, settings=settings)
                    for s in seeds]  # fmt: skip
        reached["placement"] = sum(outcome.reached for outcome in outcomes)
        failures["placement"] = dict(Counter(_code(o.status) for o in outcomes if not o.reached))
        done["placement"], run["placement"] = sum(outcome.jumps for outcome in outcomes), trials
        replans = sum(outcome.replans for outcome in outcomes)
        law_us = law_us_per_jump(model, sides, plan, settings.array())
    else:
        reached["placement"], failures["placement"] = 0, {NO_PLAN: trials}
        done["placement"], run["placement"] = 0, 0
    return WorldOutcome(label, plan.reaches_goal, trials, reached, failures, done, run,
                        {"open-loop": reach_seconds, "placement": plan.seconds}, law_us, replans,
                        (float(PSI0_DEG[column]), float(ZETA0[row])))  # fmt: skip


def _code(status: int) -> str:
    return CAPPED if status == OK else Failure(status).code


def foothold_study(
    model: ModelParams,
    worlds: list[tuple[str, World]],
    goal: float,
    state,
    *,
    trials: int,
    seed: int = 0,
    noise: NoiseModel | None = None,
    foot_y: float = 0.0,
    cap: int = 200,
    chunk_map: ChunkMap = in_process,
    progress: Progress | None = None,
) -> FootholdStudy:
    """Both methods on every ``(label, world)`` to a foot at ``goal`` [l0] from touchdown 0 (the
    foot on the left side at ``foot_y``, the body arriving with ``state``; None: the 30:0.9
    gait's velocity), ``trials`` a world."""
    if not 1 <= len(worlds) <= MAX_WORLDS:
        raise ParameterError("worlds", f"must name 1 to {MAX_WORLDS} worlds, got {len(worlds)}")
    trials = int(check_range("trials", trials, 1, MAX_TRIALS, low_open=False, high_open=False))
    seed = int(check_range("seed", seed, 0, 2**62, low_open=False))
    cap = int(check_range("cap", cap, 1, 100_000, low_open=False, high_open=False))
    for label, world in worlds:
        check_goal(world, goal, foot_y, name=label)
    state = start_velocity(model) if state is None else state
    velocity = tuple(float(v) for v in check_section_state(state))
    noise = NoiseModel() if noise is None else noise
    arguments = [(model, label, world, goal, velocity, foot_y, trials, seed, noise, cap) for label, world in worlds]
    outcomes = chunk_map(study_world, arguments, progress)
    return FootholdStudy(goal, trials, seed, noise, tuple(outcomes), velocity)
