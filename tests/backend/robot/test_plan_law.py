"""The plan's law on the robot (backend/robot/plan_law.py), touchdown by touchdown: a foot off the
planned foothold ends the run said as such, a foot at the goal ends it done, and the constants it
keeps to stay light agree with sim_core's."""

import pytest

from backend.robot import plan_law
from backend.robot.plan_law import PlanLaw
from backend.robot.run_endings import RunEnds
from backend.robot.touchdown import Touchdown
from sim_core import get_preset
from sim_core.control import placement
from sim_core.model.walls import Wall
from sim_core.planning.launch import start_velocity
from sim_core.planning.live import LivePlan
from sim_core.planning.planner import plan_climb
from sim_core.world.random_world import random_world

PAPER = get_preset("paper")


def law_for(goal_l0: float = 3.0) -> tuple[PlanLaw, list[dict]]:
    model = PAPER.to_model()
    world = random_world(3, width=model.d_hat)
    steps = [step.to_dict() for step in plan_climb(model, world, goal_l0, start_velocity(model), seed=3).steps]
    return PlanLaw(LivePlan.of(model, world, steps), goal_l0 * PAPER.leg_length, PAPER.leg_length), steps


def touchdown_at(step: dict, *, foot_y: float) -> Touchdown:
    """Detected touchdown 0 (the plan's row 1), its foot at ``foot_y`` [l0] on the planned side."""
    metres = PAPER.leg_length
    wall = Wall.LEFT if step["side"] == "left" else Wall.RIGHT
    state = (-abs(step["velocity"][0]), step["velocity"][1])  # flipped to the left wall
    return Touchdown(0, 1.0, wall, state, foot_y * metres + 0.1, foot_y * metres, 20, body_x=wall * 0.1)


def test_a_foot_off_its_foothold_ends_the_run_said_as_such():
    law, steps = law_for()
    planned_y = steps[1]["target"][1]
    with pytest.raises(RunEnds, match=rf"^missed foothold: touchdown 1 on the {steps[1]['side']} side's segment"):
        law.command(touchdown_at(steps[1], foot_y=planned_y + 0.9), 0.0, 0.5)


def test_a_foot_at_the_goal_ends_the_run_at_its_goal():
    law, steps = law_for(goal_l0=1.0)
    with pytest.raises(RunEnds, match=r"^goal reached: touchdown 1's foot at"):
        law.command(touchdown_at(steps[1], foot_y=1.2), 0.0, 0.5)


def test_the_start_legs_are_the_plans_first_two():
    law, steps = law_for()
    legs = law.start_legs()
    assert [(round(leg.psi0_deg, 9), leg.zeta0) for leg in legs] == [(s["psi0_deg"], s["zeta0"]) for s in steps[:2]]


def test_its_constants_are_placements():
    assert (plan_law.NO_LEG, plan_law.PLACED) == (placement.OFF_PLAN, placement.PLACED)
