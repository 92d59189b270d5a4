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


def test_a_replan_from_a_tracked_lift_off_lands_its_first_jump_from_there(paper):
    import numpy as np

    from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, ZETA_DOT
    from sim_core.model.stride import liftoff_velocity
    from sim_core.world.geometry import pack
    from sim_core.world.stride import foothold_stance, world_flight

    world = random_world(12)
    sides = pack(world, paper.mu)
    plan = plan_climb(paper, world, 5.0, START)
    first = plan.steps[0]
    x, y = _body_of(first)
    final = np.empty(STATE_SIZE)
    status, _ = foothold_stance(first.velocity[0], first.velocity[1], first.leg.psi0, first.leg.zeta0, paper.record(),
                                sides, 0, first.segment, final, np.empty((0, STATE_SIZE)))  # fmt: skip
    assert status == 0
    vx, vy = liftoff_velocity(final[PSI], final[ZETA_DOT], final[PSI_DOT])
    liftoff = (x - first.leg.zeta0 * math.cos(first.leg.psi0) + math.cos(final[PSI]),
               y - first.leg.zeta0 * math.sin(first.leg.psi0) + math.sin(final[PSI]), vx, vy)  # fmt: skip
    touchdown = ((x, y, *first.velocity), 0, first.segment, (first.leg.psi0, first.leg.zeta0))
    fresh = replan(paper, world, 5.0, touchdown, liftoff=liftoff)
    assert fresh.reaches_goal and fresh.steps[-1].target[1] >= 5.0, "the plan it was on is one way up"
    second = fresh.steps[1]
    landed = world_flight(*liftoff, 0, second.leg.psi0, second.leg.zeta0, sides)
    assert landed[0] == 0 and (1, landed[5]) == (second.side, second.segment)
    assert np.array(landed[1:5]) == pytest.approx(np.array([*_body_of(second), *second.velocity]), abs=1e-12)


def _body_of(step):
    inward = 1.0 if step.side == 0 else -1.0
    return (step.target[0] + inward * step.leg.zeta0 * math.cos(step.leg.psi0),
            step.target[1] + step.leg.zeta0 * math.sin(step.leg.psi0))  # fmt: skip
