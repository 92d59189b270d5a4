"""A replay's frame (frontend/viewer/modes/painter.py) drawn on a private viser server's scene: the
touchdowns passed marked once each, finished jumps' trails kept, the body followed, and a second
run drawn as the ghost. (The shared file is held equal to these frames in test_share.py.)"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from frontend.viewer.geometry import polyline_segments, to_scene
from frontend.viewer.modes.painter import show_frame
from frontend.viewer.motion import PathClip
from frontend.viewer.recordings import Recording
from frontend.viewer.scene import FOLLOW_MARGIN, ChuteScene
from sim_core import get_preset

ROBOT = get_preset("paper")
TIME = np.round(np.arange(0.0, 4.0, 0.01), 2)  # tracker frames at 100 Hz


def recording(touchdowns, rise: float = 0.5, run_id: int = 1) -> Recording:
    """A robot run climbing ``rise`` metres a second, zigzagging between the walls."""
    clip = PathClip.from_body(TIME, 0.1 * np.sin(np.pi * TIME), rise * TIME)
    return Recording(run_id, "robot", f"run {run_id}", clip, ROBOT, None, np.array(touchdowns, dtype=float))


RUN = recording([[1.0, -1, 0.4], [2.0, 1, 0.9], [3.0, -1, 1.4]])
OTHER = recording([[0.5, -1, 0.1], [1.5, 1, 0.3]], rise=0.2, run_id=2)


@pytest.fixture
def scene(server):
    return ChuteScene(server.scene, ROBOT)


def test_a_frame_marks_the_touchdowns_passed_and_keeps_the_finished_jumps_trails(scene):
    assert show_frame(scene, RUN, None, 2.5, (0, 0)) == (2, 0)
    markers = scene.touchdown_markers
    assert markers.count == 2
    assert_allclose([node.position for node in markers.nodes], [scene.touchdown_position(-1, 0.4),
                                                                 scene.touchdown_position(1, 0.9)])  # fmt: skip
    assert scene.jump_trails.count == 1, "the jump from touchdown 0 to 1 is finished"
    assert_allclose(scene.jump_trails.nodes[0].points, polyline_segments(RUN.jump_trail(1)))
    assert_allclose(scene.trail.points, polyline_segments(RUN.trail(2.5)), err_msg="the jump under way")
    body = RUN.clip.pose_at(2.5)
    assert_allclose(scene.body.position, to_scene(body.x, body.y))
    assert not scene.ghost.visible


def test_the_next_frame_adds_only_what_happened_since(scene):
    marked = show_frame(scene, RUN, None, 2.5, (0, 0))
    assert show_frame(scene, RUN, None, 2.6, marked) == (2, 0)
    assert (scene.touchdown_markers.count, scene.jump_trails.count) == (2, 1), "nothing marked twice"
    assert show_frame(scene, RUN, None, 3.5, marked) == (3, 0)
    assert (scene.touchdown_markers.count, scene.jump_trails.count) == (3, 2)


def test_the_replay_follows_the_body_up_the_chute(scene):
    show_frame(scene, RUN, None, 3.0, (0, 0))
    height = RUN.clip.pose_at(3.0).y
    assert_allclose(scene.root.position, (0.0, 0.0, FOLLOW_MARGIN - height))


def test_a_second_run_is_drawn_as_the_ghost_with_its_own_jumps(scene):
    assert show_frame(scene, RUN, OTHER, 2.0, (0, 0)) == (2, 2)
    ghost = OTHER.clip.pose_at(2.0)
    assert scene.ghost.visible and scene.ghost_trail.visible
    assert_allclose(scene.ghost.position, to_scene(ghost.x, ghost.y))
    assert_allclose(scene.ghost_trail.points, polyline_segments(OTHER.trail(2.0)))
    assert scene.ghost_jump_trails.count == 1, "the ghost's finished jump; its touchdowns are not marked"
    assert scene.touchdown_markers.count == 2
    assert show_frame(scene, RUN, None, 2.1, (2, 2)) == (2, 0)
    assert not scene.ghost.visible, "no second run: no ghost"
