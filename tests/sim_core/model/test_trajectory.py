"""Trajectories: consistent with the map, un-flipped into wall coordinates, convertible to SI."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import ControlSchedule, get_preset, iterate_map, simulate_trajectory
from sim_core.model.trajectory import FLIGHT, STANCE


@pytest.fixture(scope="module")
def climb(paper, alternating):
    return simulate_trajectory(paper, alternating, (-0.8, -0.15), 6, sample_rate=400)


def test_events_match_the_map(paper, alternating, climb):
    orbit = iterate_map(paper, alternating, (-0.8, -0.15), 6)
    assert_allclose(climb.section_states, orbit.states, rtol=0, atol=0)
    assert_allclose(climb.rises, orbit.rises, rtol=0, atol=0)
    assert climb.failure is None and np.all(np.diff(climb.touchdown_times) > 0)


def test_walls_alternate_and_body_stays_between(paper, climb):
    half = paper.d_hat / 2
    assert np.all(np.abs(climb.x) < half)
    for k in range(6):
        feet = climb.foot_x[(climb.jump == k) & (climb.phase == STANCE)]
        assert_allclose(feet, -half if k % 2 == 0 else half, err_msg=f"stance {k} foot on its wall")


def test_leg_geometry_is_consistent(climb):
    length = np.hypot(climb.x - climb.foot_x, climb.y - climb.foot_y)
    assert_allclose(length, climb.zeta, rtol=0, atol=1e-12)
    assert np.all(climb.zeta[climb.phase == STANCE] <= 1.0 + 1e-12)


def test_flight_is_ballistic(climb):
    flight = (climb.phase == FLIGHT) & (climb.jump == 2)
    t, y = climb.time[flight], climb.y[flight]
    curvature = np.polyfit(t, y, 2)[0]
    assert curvature == pytest.approx(-0.5, abs=1e-9)


def test_height_is_continuous(climb):
    step = np.abs(np.diff(climb.y))
    assert step.max() < 0.05, "samples every 1/400 time unit move the body less than 0.05 l0"


def test_si_conversion(climb):
    robot = get_preset("paper")
    si = climb.to_si(robot)
    assert si.units == "SI"
    assert_allclose(si.y, climb.y * robot.leg_length)
    assert_allclose(si.time, climb.time * math.sqrt(robot.leg_length / robot.gravity))
    assert_allclose(si.psi, climb.psi)


def test_failure_ends_the_trajectory(paper, symmetric):
    trajectory = simulate_trajectory(paper, symmetric, (-0.3, 5.0), 5)
    assert trajectory.failure is not None and trajectory.failed_jump == 1
    assert trajectory.rises.size == 0 and trajectory.time.size > 0, "the failed stance is still drawn"


def test_collapsed_touchdown_is_a_failure_not_an_error(paper):
    schedule = ControlSchedule.from_degrees([(30.0, 1e-5)])
    trajectory = simulate_trajectory(paper, schedule, (-0.93, -0.17), 3)
    assert trajectory.failure is not None and trajectory.failure.code == "collapse"
    assert np.all(np.diff(trajectory.time) >= 0)
