"""The model's motion for the view (frontend/viewer/simulated_climb.py) agrees with the simulator's
map, jump for jump: the simulated climb's states and rises, its walls and feet, controls read at
touchdown and lift-off as the robot reads them, and its ends (a failing jump, the floor)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from frontend.viewer.simulated_climb import Controls, SimulatedClimb, model_jump
from sim_core import ControlSchedule, LegControl, get_preset, iterate_map
from sim_core.climb.records import CHUTE_TOP, FLOOR, ClimbEnd
from sim_core.climb.sequencer import start_height
from sim_core.model.walls import Wall, wall_of

ROBOT = get_preset("paper")
PERIOD_1 = LegControl.from_degrees(30, 0.90)
START = (-0.9339, -0.1661)
RTOL_MAP = 1e-9  # the view and the map run the same kernel: only sampling differs, not states


def _climb(left=PERIOD_1, right=PERIOD_1) -> SimulatedClimb:
    return SimulatedClimb(Controls(left, right, ROBOT), START)


@pytest.mark.parametrize("right", [PERIOD_1, LegControl.from_degrees(30, 0.87)])
def test_simulated_climb_follows_the_map(right):
    climb = _climb(PERIOD_1, right)
    climb.pose_at(6.0)
    jumps = len(climb.plans) - 1
    orbit = iterate_map(ROBOT.to_model(), ControlSchedule.of(PERIOD_1, right), START, jumps)
    assert_allclose([plan.state for plan in climb.plans], orbit.states[: jumps + 1], rtol=RTOL_MAP, atol=1e-12)
    rises = np.array([plan.rise for plan in climb.plans[:jumps]]) / ROBOT.leg_length
    assert_allclose(rises, orbit.rises[:jumps], rtol=RTOL_MAP, err_msg="height gain per jump [l0]")


def test_jumps_alternate_walls_and_feet_sit_on_them():
    climb = _climb()
    climb.pose_at(4.0)
    half = 0.5 * ROBOT.wall_distance
    for k, plan in enumerate(climb.plans):
        assert plan.wall is wall_of(k)
        assert plan.clip.foot_x[0] == pytest.approx(plan.wall * half), f"jump {k} foot on its wall"
    first = climb.plans[0].clip
    assert first.y[0] == pytest.approx(start_height(PERIOD_1, ROBOT)), "the first foot touches at the floor"
    assert first.foot_y[0] == pytest.approx(FLOOR, abs=1e-12)


def test_the_body_moves_continuously_across_touchdowns():
    climb = _climb()
    times = np.arange(0.0, 5.0, 1 / 240)
    body = np.array([(pose.x, pose.y) for pose in map(climb.pose_at, times)])
    step = np.hypot(*np.diff(body, axis=0).T)
    assert step.max() < 0.02, "no jumps in the drawn position between frames [m]"


def test_a_control_change_shows_from_the_next_touchdown():
    climb = _climb()
    first = climb.plans[0]
    during_stance = 0.5 * (first.clip.start + first.liftoff_time)
    climb.pose_at(during_stance)
    deeper = LegControl.from_degrees(30, 0.86)
    climb.set_controls(Controls(deeper, deeper, ROBOT))
    climb.pose_at(first.clip.end - 1e-6)
    assert climb.plans[0].leg == PERIOD_1, "the stance under way keeps its controls"
    assert climb.plans[0].next_leg == deeper, "the next leg is read at lift-off"
    assert_allclose(climb.plans[0].clip.x[:10], first.clip.x[:10], err_msg="same stance")
    climb.pose_at(climb.plans[0].clip.end + 0.01)
    assert climb.plans[1].leg == deeper


def test_a_change_after_liftoff_waits_for_the_jump_after():
    climb = _climb()
    first = climb.plans[0]
    climb.pose_at(first.liftoff_time + 0.01)
    deeper = LegControl.from_degrees(30, 0.86)
    climb.set_controls(Controls(deeper, deeper, ROBOT))
    climb.pose_at(climb.plans[0].clip.end + 0.01)
    assert climb.plans[1].leg == PERIOD_1, "the leg in flight was set at lift-off"
    assert climb.plans[1].next_leg == deeper


def test_a_failing_climb_stops_and_says_why():
    weak = LegControl.from_degrees(30, 0.985)  # too little energy to reach the other wall
    climb = _climb(weak, weak)
    pose = climb.pose_at(60.0)
    assert climb.ended
    assert climb.current.failure is not None
    assert climb.pose_at(61.0) == pose, "the pose holds after the failure"


def test_a_descending_climb_stops_at_the_floor_and_names_it():
    weak = LegControl.from_degrees(30, 0.99)  # beyond jumping in place: the gait descends
    climb = _climb(weak, weak)
    pose = climb.pose_at(120.0)
    assert climb.ended and climb.current.failure is ClimbEnd.FLOOR
    assert len(climb.plans) > 1 and all(plan.rise < 0 for plan in climb.plans[:-1]), "it descended"
    assert pose.y == pytest.approx(FLOOR), "it stops where the body meets the floor"
    assert min(plan.clip.y.min() for plan in climb.plans) >= FLOOR, "never below it"


def test_a_climbing_gait_stops_at_the_chutes_top_and_names_it():
    """An open loop climbed to 9.8 m in the lab's 2 m chute (issue 40): the climb ends at the jump
    that would land above the top, and says so."""
    climb = _climb()  # the paper's climbing gait
    pose = climb.pose_at(600.0)
    assert climb.ended and climb.current.failure is ClimbEnd.TOP and "top" in climb.current.failure.message
    touchdowns = [float(plan.clip.y[0]) for plan in climb.plans]
    assert max(touchdowns) <= CHUTE_TOP < climb.current.next_height, "every touchdown inside; the next one above"
    assert climb.pose_at(601.0) == pose, "the pose holds after the end"


def test_model_jump_mirrors_on_the_right_wall():
    left = model_jump(ROBOT, START, PERIOD_1, PERIOD_1, wall=Wall.LEFT, start_time=0.0, start_height=0.2)
    right = model_jump(ROBOT, START, PERIOD_1, PERIOD_1, wall=Wall.RIGHT, start_time=0.0, start_height=0.2)
    assert_allclose(right.clip.x, -left.clip.x)
    assert_allclose(right.clip.y, left.clip.y)


def test_each_jump_starts_where_and_when_the_one_before_ends_and_the_last_where_it_stopped():
    climb = _climb()
    climb.pose_at(3.0)
    for plan, after in zip(climb.plans, climb.plans[1:], strict=False):
        gap = after.clip.start - plan.clip.end  # the touchdown falls between the last sample and the next
        assert 0.0 < gap < 0.01, f"jump {after.jump.start.jump} starts when the one before touches down"
        assert plan.next_height == pytest.approx(after.clip.y[0]), "at the body height its jump predicted"
    weak = LegControl.from_degrees(30, 0.99)  # it descends to the floor
    ended = _climb(weak, weak)
    ended.pose_at(120.0)
    assert ended.current.next_height == pytest.approx(FLOOR), "after the end: where the body stopped"
    deeper = LegControl.from_degrees(30, 0.86)
    controls = Controls(PERIOD_1, deeper, ROBOT)
    assert (controls.leg_for(Wall.LEFT), controls.leg_for(Wall.RIGHT)) == (PERIOD_1, deeper)


@pytest.mark.parametrize("name", ["pid", "lqr", "deadbeat"])
def test_a_closed_loop_climbs_as_the_benchmarks_compiled_loop_does(name):
    """With a law set, each touchdown's command is the next touchdown's leg, as in the benchmark's
    compiled trial (sim_core.control.study.controlled_loop) without noise: the same touchdown
    heights, jump for jump, and the target held."""
    from experiments.control_study import Config, laws_for
    from sim_core.control.study import controlled_loop
    from sim_core.model.noise import NoiseModel

    config = Config(controllers=(name,), target_m=0.5, jumps=30)
    loop, (law,) = laws_for(ROBOT.to_model(), config, ROBOT.leg_length)
    first = LegControl.from_degrees(35.0, 0.9)
    view = SimulatedClimb(Controls(first, first, ROBOT), tuple(loop.start))
    view.set_law(law)
    view.reset()
    view.pose_at(60.0)
    heights = np.full(31, np.nan)
    kind, parameters = law.kernel_args()
    no_noise = NoiseModel(0.0, 0.0, 0.0, 0.0).record()
    status, _ = controlled_loop(*loop.start, first.psi0, first.zeta0, kind, parameters, 0, no_noise,
                                ROBOT.to_model().record(), heights, np.zeros(30, dtype=np.bool_))  # fmt: skip
    shown = np.array([plan.jump.start.body_height for plan in view.plans[:31]]) / ROBOT.leg_length
    assert status == 0 and len(view.commands) >= 30
    assert_allclose(shown, heights, rtol=1e-9, atol=1e-12)
    assert abs(view.plans[30].jump.start.body_height - 0.5) < 0.01
    assert view.plans[1].leg == view.commands[0].leg, "touchdown 0's command is touchdown 1's leg"


def test_opening_the_loop_gives_the_sliders_back():
    climb = _climb()
    law_free = [plan.next_leg for plan in climb.plans]
    climb.set_law(None)
    climb.reset()
    assert climb.stepped is None and climb.commands == [] and [plan.next_leg for plan in climb.plans] == law_free
