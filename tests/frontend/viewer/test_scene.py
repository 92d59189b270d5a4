"""The chute in viser (frontend/viewer/scene.py), drawn on a private server's scene through its
handles: walls and ruler that grow ahead of the robot and never shrink, the robot's body, legs and
foot as a pose has them, the chute sliding down under a followed robot, the ghost, and the jump
history (touchdown markers on the walls' faces, past trails) cleared for a new run.

What a replay frame draws is held equal to the shared file's in tests/frontend/viewer/test_share.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from frontend.viewer.geometry import polyline_segments, to_scene
from frontend.viewer.motion import Pose
from frontend.viewer.scene import (
    CAMERA_LOOK_AT,
    CAMERA_POSITION,
    FOLLOW_MARGIN,
    HEADROOM,
    TOUCHDOWN_MARKERS,
    WALL_THICKNESS,
    ChuteScene,
    place_camera,
)
from sim_core import LegControl, get_preset
from sim_core.model.trajectory import FLIGHT, STANCE
from sim_core.model.walls import Wall

ROBOT = get_preset("paper")
HALF = 0.5 * ROBOT.wall_distance  # [m] the centre line to a wall's face
IDLE = LegControl.from_degrees(30, 0.9)


def stance_pose(y: float = 0.3, phase: int = STANCE) -> Pose:
    """The body at height ``y`` [m], its leg on the left wall, compressed to 0.9 l0."""
    return Pose(time=0.0, x=-0.05, y=y, foot_x=-HALF, foot_y=y - 0.1, zeta=0.9 * ROBOT.leg_length,
                phase=phase, leg_wall=Wall.LEFT, jump=0)  # fmt: skip


@pytest.fixture
def scene(server):
    return ChuteScene(server.scene, ROBOT)


def test_the_walls_reach_above_the_robot_in_half_metres_with_headroom():
    assert ChuteScene.top_for(1.0) == 2.5
    assert_allclose(ChuteScene.top_for(np.array([-1.0, 0.0, 0.1, 0.6])), [1.5, 1.5, 2.0, 2.5])
    heights = np.linspace(0.0, 5.0, 101)
    assert np.all(ChuteScene.top_for(heights) >= heights + HEADROOM), "always the headroom above the robot"


def test_the_walls_and_the_ruler_grow_and_never_shrink(scene):
    assert scene.top == 2.5, "made reaching a robot at 1 m"
    assert scene.growth(0.4) is None, "high enough already"
    growth = scene.growth(2.0)
    assert growth.top == 3.5 and growth.section == "/chute/ruler/part_1", "a second section of ruler"
    assert [text for _name, text, _position in growth.labels] == ["2.75 m", "3.00 m", "3.25 m", "3.50 m"]
    assert growth.labels[0][0] == "/chute/ruler/label_11", "numbered after the 11 labels of 0 … 2.5 m"
    spine = growth.segments[0]
    assert (spine[0, 2], spine[1, 2]) == (2.5, 3.5), "the spine goes on from the old top"
    scene.reach(2.0)
    assert scene.top == 3.5
    for wall, side in zip(scene.walls, (-1, 1), strict=True):
        assert_allclose(wall.dimensions, (WALL_THICKNESS, 0.35, 3.5))
        assert_allclose(wall.position, (side * (HALF + 0.5 * WALL_THICKNESS), 0.0, 1.75))
    scene.reach(0.0)
    assert scene.top == 3.5 and scene.growth(2.0) is None, "the robot falling back shrinks nothing"
    assert scene.growth(2.01).section == "/chute/ruler/part_2"


def test_a_stance_pose_draws_the_body_its_legs_and_the_foot_on_the_wall(scene):
    pose = stance_pose()
    trail = np.array([[0.0, 0.1], [-0.02, 0.2], [-0.05, 0.3]])
    scene.show(pose, IDLE, trail, follow=False)
    assert_allclose(scene.body.position, to_scene(pose.x, pose.y))
    assert_allclose(scene.foot.position, to_scene(-HALF, pose.y - 0.1))
    assert scene.foot.visible and scene.legs[Wall.LEFT].visible and scene.legs[Wall.RIGHT].visible
    stance = scene.legs[Wall.LEFT].points
    assert_allclose(stance[0, 0], (0.0, 0.0, 0.0), atol=1e-12, err_msg="the leg hangs from the body")
    assert_allclose(stance[-1, 1], to_scene(-HALF - pose.x, -0.1), atol=1e-12, err_msg="and ends at the foot")
    idle = scene.legs[Wall.RIGHT].points[-1, 1]
    assert idle[0] > 0 and idle[2] < 0, "the idle leg reaches down toward the right wall"
    assert_allclose(scene.trail.points, polyline_segments(trail))
    assert_allclose(scene.root.position, (0.0, 0.0, 0.0), err_msg="not followed: the chute stays")


def test_in_flight_the_foot_is_hidden_and_without_the_idle_leg_one_leg_is_drawn(scene):
    scene.show(stance_pose(phase=FLIGHT), None, None, follow=False)
    assert not scene.foot.visible
    assert scene.legs[Wall.LEFT].visible and not scene.legs[Wall.RIGHT].visible


def test_tracker_poses_draw_the_body_alone(scene):
    scene.show(stance_pose(), IDLE, None, follow=False)
    tracked = Pose(0.0, 0.02, 0.5, math.nan, math.nan, math.nan, -1, Wall.RIGHT, 0)
    scene.show(tracked, None, None, follow=False)
    assert_allclose(scene.body.position, to_scene(0.02, 0.5))
    assert not scene.foot.visible and not any(leg.visible for leg in scene.legs.values()), "legs unknown"


def test_following_slides_the_chute_down_to_keep_the_robot_in_view(scene):
    scene.show(stance_pose(y=0.3), None, None, follow=True)
    assert_allclose(scene.root.position, (0.0, 0.0, 0.0), err_msg="low down: nothing to follow")
    scene.show(stance_pose(y=2.0), None, None, follow=True)
    assert_allclose(scene.root.position, (0.0, 0.0, FOLLOW_MARGIN - 2.0))
    assert scene.top == ChuteScene.top_for(2.0), "the walls grew ahead of it"
    scene.show(stance_pose(y=2.5), None, None, follow=False)
    assert_allclose(scene.root.position, (0.0, 0.0, FOLLOW_MARGIN - 2.0), err_msg="follow off: the chute stays put")


def test_the_ghost_is_drawn_with_its_trail_and_hidden_by_none(scene):
    ghost = stance_pose(y=0.4)
    trail = np.array([[0.0, 0.3], [0.0, 0.4]])
    scene.show_ghost(ghost, trail)
    assert scene.ghost.visible and scene.ghost_trail.visible
    assert_allclose(scene.ghost.position, to_scene(ghost.x, ghost.y))
    assert_allclose(scene.ghost_trail.points, polyline_segments(trail))
    scene.show_ghost(ghost, trail[:1])
    assert scene.ghost.visible and not scene.ghost_trail.visible, "one point is no trail"
    scene.show_ghost(None)
    assert not scene.ghost.visible and not scene.ghost_trail.visible


def test_touchdowns_are_marked_on_the_walls_faces_the_last_ones_kept(scene):
    scene.add_touchdown(Wall.RIGHT, 0.4)
    marker = scene.touchdown_markers.nodes[0]
    assert marker.visible and marker.name == "/chute/touchdowns/0"
    assert_allclose(marker.position, (HALF, 0.0, 0.4))
    for k in range(TOUCHDOWN_MARKERS):
        scene.add_touchdown(Wall.LEFT, 0.5 + 0.01 * k)
    assert len(scene.touchdown_markers.nodes) == TOUCHDOWN_MARKERS
    assert_allclose(marker.position, (-HALF, 0.0, 0.5 + 0.01 * (TOUCHDOWN_MARKERS - 1)), err_msg="the newest")


def test_finished_jumps_keep_their_trails_until_the_history_is_cleared(scene):
    scene.add_jump_trail(np.array([[0.0, 0.1]]))
    assert scene.jump_trails.count == 0, "one point is no trail"
    path = np.array([[0.0, 0.1], [0.05, 0.2], [0.1, 0.25]])
    scene.add_jump_trail(path)
    scene.add_ghost_jump_trail(path)
    scene.add_touchdown(Wall.LEFT, 0.2)
    assert_allclose(scene.jump_trails.nodes[0].points, polyline_segments(path))
    assert scene.jump_trails.nodes[0].visible and scene.ghost_jump_trails.nodes[0].visible
    scene.live_trail.extend(path)
    scene.show(stance_pose(y=2.0), None, path, follow=True)
    scene.clear_history()
    rings = (scene.touchdown_markers, scene.jump_trails, scene.ghost_jump_trails, scene.live_trail.finished)
    assert not any(node.visible for ring in rings for node in ring.nodes)
    assert len(scene.live_trail.piece) == 0 and not scene.live_trail.now.points.any()
    assert not scene.trail.points.any(), "the current jump's trail emptied"
    assert_allclose(scene.root.position, (0.0, 0.0, 0.0), err_msg="back to the floor")
    assert scene.offset == 0.0


def test_the_camera_starts_in_front_of_the_chute_level_with_the_robot(server):
    place_camera(server)
    assert_allclose(server.initial_camera.position, CAMERA_POSITION)
    assert_allclose(server.initial_camera.look_at, CAMERA_LOOK_AT)
    assert_allclose(server.initial_camera.up, (0.0, 0.0, 1.0))
