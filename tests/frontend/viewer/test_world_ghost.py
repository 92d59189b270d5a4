"""The model's jump in a world from a live touchdown (frontend/viewer/world_ghost.py), on its own:
a touchdown the model slips at once is drawn as its one pose with the failure, and a model of
another leg length jumps in the same sides in metres (tests/frontend/viewer/modes/test_live_world.py
tests the ghost live mode draws with it)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from frontend.viewer.world_ghost import in_leg_lengths, world_jump
from sim_core import get_preset
from sim_core.model.controls import LegControl
from sim_core.model.failures import Failure
from sim_core.model.walls import Wall
from sim_core.world.world import Side, World

ROBOT = get_preset("paper")
L0 = ROBOT.leg_length
LEG = LegControl.from_degrees(30, 0.9)
# The left side has no grip below 1.5 l0; the right one holds everywhere.
WORLD = World(
    Side(np.array([[-1.3, 0.0], [-1.3, 1.5], [-1.3, 4.0]]), np.array([0.0, math.inf])),
    Side(np.array([[1.1, 0.0], [1.1, 4.0]]), np.array([math.inf])),
)


def test_a_touchdown_that_slips_at_once_is_drawn_as_its_one_pose():
    ghost = world_jump(ROBOT, WORLD, (-0.9, -0.1), LEG, LEG, wall=Wall.LEFT, start_time=2.0, foot_height=0.5 * L0)
    assert ghost.failure is Failure.SLIP and len(ghost.clip.time) == 1
    pose = ghost.clip.pose_at(3.0)
    body = (-1.3 + LEG.zeta0 * math.cos(LEG.psi0), 0.5 + LEG.zeta0 * math.sin(LEG.psi0))
    np.testing.assert_allclose((pose.time, pose.x, pose.y), (2.0, body[0] * L0, body[1] * L0), atol=1e-12)
    np.testing.assert_allclose((pose.foot_x, pose.foot_y), (-1.3 * L0, 0.5 * L0), atol=1e-12)


def test_a_model_of_another_leg_length_jumps_in_the_same_sides_in_metres():
    longer = dataclasses.replace(ROBOT, leg_length=1.25 * L0)
    world = in_leg_lengths(WORLD, L0, longer)
    assert in_leg_lengths(WORLD, L0, ROBOT) is WORLD
    np.testing.assert_allclose(world.right.points * longer.leg_length, WORLD.right.points * L0)
    ghost = world_jump(longer, world, (-0.9, -0.1), LEG, LEG, wall=Wall.RIGHT, start_time=0.0, foot_height=0.5)
    assert ghost.failure is None
    np.testing.assert_allclose(ghost.clip.foot_x[0], 1.1 * L0, rtol=1e-12, err_msg="its foot on the right side")
    np.testing.assert_allclose(ghost.clip.foot_x[-1], -1.3 * L0, rtol=1e-12, err_msg="landing on the left one")
