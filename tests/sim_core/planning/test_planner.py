"""The planner: a plan replayed by climb_world lands where it says and reaches the goal; its
chance is what its draws say; no way up is said with the highest foot; bad goals are refused."""

import math

import numpy as np
import pytest

from sim_core.model.errors import ParameterError
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.planning.planner import plan_climb
from sim_core.world.climb import climb_world
from sim_core.world.named import named_world
from sim_core.world.random_world import random_world
from sim_core.world.world import Side, World

START = (-1.0, 0.5)


@pytest.mark.parametrize("world", [named_world("staircase", 2.42), random_world(2)], ids=["staircase", "random-2"])
def test_a_plan_replayed_lands_where_it_says_and_reaches_the_goal(paper, world):
    plan = plan_climb(paper, world, 5.0, START)
    assert plan.reaches_goal and 0.0 < plan.chance <= 1.0
    replay = climb_world(paper, world, plan.schedule, START, len(plan.steps) - 1)
    assert replay.failure is None
    for step, row, side, segment in zip(plan.steps, replay.states, replay.sides, replay.segments, strict=True):
        foot = (row[0] + (-1.0 if side == 0 else 1.0) * step.leg.zeta0 * math.cos(step.leg.psi0),
                row[1] - step.leg.zeta0 * math.sin(step.leg.psi0))  # fmt: skip
        assert (step.side, step.segment) == (side, segment) and step.target == pytest.approx(foot, abs=1e-12)
    assert plan.steps[-1].target[1] >= 5.0 and plan.highest >= 5.0


def test_without_noise_every_draw_is_the_nominal_jump_so_the_chance_is_one(paper):
    plan = plan_climb(paper, named_world("staircase", paper.d_hat), 3.0, START, noise=NO_NOISE)
    assert plan.reaches_goal and plan.chance == 1.0
    rough = NoiseModel(psi0_deg=8.0, zeta0=0.02, velocity=0.1)
    assert plan_climb(paper, named_world("staircase", paper.d_hat), 3.0, START, noise=rough).chance < 1.0, (
        "with legs 8 degrees off some draws miss their foothold"
    )


def test_no_way_up_is_said_with_the_highest_foot_and_bad_goals_are_refused(paper):
    walls = np.array([[-1.21, 0.0], [-1.21, 1.0], [-1.21, 9.0]])
    greasy = World(Side(walls, np.array([np.nan, 0.0])), Side(walls * [-1, 1], np.array([np.nan, 0.0])), "greasy")
    plan = plan_climb(paper, greasy, 6.0, START, beam=8)
    assert not plan.reaches_goal and plan.chance == 0.0 and plan.highest < 1.0 + 1e-9
    for goal, words in ((0.0, "above the start"), (20.0, "top")):
        with pytest.raises(ParameterError, match=words):
            plan_climb(paper, greasy, goal, START)
