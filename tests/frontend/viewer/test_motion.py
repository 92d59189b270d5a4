"""Sampled motion (frontend/viewer/motion.py): a clip's pose at any instant, interpolated within a
phase and clamped to its ends, one instant or many at once; tracker data without legs."""

import math

import numpy as np
import pytest

from frontend.viewer.motion import UNKNOWN_PHASE, PathClip
from frontend.viewer.simulated_climb import Controls, SimulatedClimb
from sim_core import LegControl, get_preset
from sim_core.model.walls import Wall

ROBOT = get_preset("paper")
PERIOD_1 = LegControl.from_degrees(30, 0.90)
START = (-0.9339, -0.1661)


def test_path_clip_interpolates_and_clamps():
    clip = PathClip.from_body([0.0, 1.0, 2.0], [0.0, 1.0, 1.0], [0.0, 2.0, 4.0])
    assert clip.pose_at(0.5).x == pytest.approx(0.5)
    assert clip.pose_at(1.5).y == pytest.approx(3.0)
    assert clip.pose_at(-1.0).y == 0.0 and clip.pose_at(9.0).y == 4.0
    assert math.isnan(clip.pose_at(0.5).zeta), "tracker data has no legs"
    assert clip.body_until(1.0).shape == (2, 2)


def test_a_clip_sampled_at_many_times_is_its_pose_at_each():
    climb = SimulatedClimb(Controls(PERIOD_1, LegControl.from_degrees(30, 0.87), ROBOT), START)
    climb.pose_at(3.0)
    clip = climb.plans[2].clip  # a jump: stance then flight, the phases not interpolated across
    times = np.r_[clip.start - 0.1, np.linspace(clip.start, clip.end, 97), clip.time[5], clip.end + 0.1]
    sampled = clip.sampled_at(times)
    for k, t in enumerate(times):
        pose = clip.pose_at(t)
        row = (sampled.time[k], sampled.x[k], sampled.y[k], sampled.foot_x[k], sampled.foot_y[k], sampled.zeta[k])
        assert row == (pose.time, pose.x, pose.y, pose.foot_x, pose.foot_y, pose.zeta), t
        assert (sampled.phase[k], sampled.leg_wall[k], sampled.jump[k]) == (pose.phase, pose.leg_wall, pose.jump)
    body = PathClip.from_body([0.0, 1.0], [0.0, 1.0], [0.0, 2.0]).sampled_at([0.25, 3.0])
    assert body.y.tolist() == [0.5, 2.0] and np.isnan(body.zeta).all()


def test_tracker_frames_are_a_clip_of_the_body_alone():
    clip = PathClip.from_body([0.0, 0.5, 1.0], [-0.1, 0.0, 0.1], [0.2, 0.3, 0.4], jump=[0, 0, 1])
    assert (clip.phase == UNKNOWN_PHASE).all() and np.isnan(clip.foot_x).all()
    assert clip.leg_wall.tolist() == [Wall.RIGHT, Wall.LEFT, Wall.LEFT], "the leg drawn reaches across the chute"
    assert clip.pose_at(0.75).jump == 0 and clip.pose_at(1.0).jump == 1
    with pytest.raises(ValueError, match="at least one sample"):
        PathClip.from_body([], [], [])


def test_the_trail_since_an_instant_starts_at_the_sample_before_it():
    clip = PathClip.from_body([0.0, 1.0, 2.0, 3.0], [0.0, 0.1, 0.2, 0.3], [0.0, 1.0, 2.0, 3.0])
    assert clip.body_until(2.5, since=1.5).tolist() == [[0.1, 1.0], [0.2, 2.0]], "from the sample at 1 s"
    assert clip.body_until(2.0).tolist() == [[0.0, 0.0], [0.1, 1.0], [0.2, 2.0]], "from the start"
    assert (clip.start, clip.end) == (0.0, 3.0)
