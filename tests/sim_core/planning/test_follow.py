"""Following a plan under noise: without noise the law replays the plan to the goal with no
replan; a trial depends on its seed alone; a replan starts at the touchdown it is given."""

import math

import pytest

from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.planning.follow import follow_plan
from sim_core.planning.planner import plan_climb, replan
from sim_core.world.random_world import random_world

START = (-1.0, 0.5)


@pytest.mark.parametrize("seed", [0, 6, 11])
def test_without_noise_the_law_follows_the_plan_to_the_goal_without_replanning(paper, seed):
    world = random_world(seed)
    plan = plan_climb(paper, world, 5.0, START)
    assert plan.reaches_goal
    outcome = follow_plan(paper, world, plan, 5.0, NO_NOISE, seed)
    assert outcome.reached and outcome.replans == 0 and outcome.jumps == len(plan.steps) - 1


def test_a_trial_is_its_seed_and_the_noise_changes_it(paper):
    world = random_world(2)
    plan = plan_climb(paper, world, 5.0, START)
    noise = NoiseModel(psi0_deg=1.0)
    outcomes = [follow_plan(paper, world, plan, 5.0, noise, seed) for seed in (7, 7, 8, 9, 10, 11)]
    assert (outcomes[0].reached, outcomes[0].status, outcomes[0].jumps, outcomes[0].replans) == (
        outcomes[1].reached, outcomes[1].status, outcomes[1].jumps, outcomes[1].replans)  # fmt: skip
    assert len({(o.reached, o.status, o.jumps, o.replans) for o in outcomes}) > 1, "different draws, different runs"


def test_a_replan_starts_at_the_touchdown_it_is_given(paper):
    world = random_world(3)
    plan = plan_climb(paper, world, 5.0, START)
    middle = plan.steps[2]
    inward = 1.0 if middle.side == 0 else -1.0
    row = (middle.target[0] + inward * middle.leg.zeta0 * math.cos(middle.leg.psi0),
           middle.target[1] + middle.leg.zeta0 * math.sin(middle.leg.psi0), *middle.velocity)  # fmt: skip
    fresh = replan(paper, world, 5.0, (row, middle.side, middle.segment, (middle.leg.psi0, middle.leg.zeta0)))
    assert fresh.reaches_goal and fresh.steps[0].target == pytest.approx(middle.target, abs=1e-12)
    assert (fresh.steps[0].side, fresh.steps[0].segment) == (middle.side, middle.segment)
    assert fresh.steps[-1].target[1] >= 5.0
    done = replan(paper, world, middle.target[1] - 0.1, (row, middle.side, middle.segment,
                                                        (middle.leg.psi0, middle.leg.zeta0)))  # fmt: skip
    assert done.reaches_goal and len(done.steps) == 1, "a goal at or below this foot is reached already"
