"""The climb sequencer (sim_core.climb.sequencer): walls and legs, the next leg at lift-off, noise, the floor
(its records: test_climb_records.py)."""

import dataclasses
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sim_core import ControlSchedule, LegControl, get_preset, simulate_trajectory
from sim_core.climb.records import FLOOR, ClimbEnd, ClimbSetup, NextLeg
from sim_core.climb.sequencer import (
    jump,
    launch,
    read_next_leg,
    replan,
    simulate_climb,
    stance,
    start_height,
    touchdown_after,
)
from sim_core.model.failures import Failure
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.trajectory import FLIGHT, STANCE
from sim_core.model.walls import Wall, wall_of

ROBOT = get_preset("paper")
SETUP = ClimbSetup(ROBOT)
LEFT_LEG, RIGHT_LEG = LegControl.from_degrees(30, 0.87), LegControl.from_degrees(30, 0.90)
START = (-0.8, -0.15)
RTOL_SUM = 1e-12  # times and heights summed jump by jump instead of along one run


def _legs(wall: Wall) -> LegControl:
    return LEFT_LEG if wall is Wall.LEFT else RIGHT_LEG


def test_jump_k_stands_on_wall_of_k_with_that_walls_leg():
    jumps = simulate_climb(SETUP, _legs, START, 5)
    assert len(jumps) == 5 and all(j.end is None for j in jumps)
    half = 0.5 * ROBOT.wall_distance
    for k, done in enumerate(jumps):
        assert done.start.jump == k and done.wall is wall_of(k)
        assert done.start.leg == _legs(wall_of(k)) and done.next.leg == _legs(wall_of(k + 1))
        assert_allclose(done.stance.foot_x, done.wall * half, err_msg=f"jump {k}'s foot is on its wall")
        assert np.all(np.sign(done.stance.x) == done.wall), "the body is on the stance wall's side of the centre"


def test_the_first_foot_touches_at_the_floor():
    start = launch(SETUP, LEFT_LEG, START)
    assert start.body_height == pytest.approx(FLOOR + 0.87 * ROBOT.leg_length * 0.5)
    assert start.body_height == start_height(LEFT_LEG, ROBOT)
    assert jump(SETUP, start, NextLeg(RIGHT_LEG)).samples.foot_y[0] == pytest.approx(FLOOR, abs=1e-12)


def test_the_next_leg_read_at_liftoff_changes_only_the_flight():
    start = launch(SETUP, LEFT_LEG, START)
    part = stance(SETUP, start)
    assert part.end is None and np.all(part.samples.phase == STANCE)
    planned = jump(SETUP, start, read_next_leg(start, RIGHT_LEG))
    deeper = jump(SETUP, start, read_next_leg(start, LegControl.from_degrees(35, 0.85)))
    for whole in (planned, deeper):
        for name in ("time", "x", "y", "foot_x", "zeta"):
            assert_array_equal(getattr(whole.stance, name), getattr(part.samples, name), err_msg=name)
        assert np.all(whole.flight.phase == FLIGHT)
    assert not np.allclose(planned.flight.foot_x, deeper.flight.foot_x[: len(planned.flight)])
    assert planned.arrival != deeper.arrival, "the flight ends where the next leg touches"


def test_noise_off_reproduces_simulate_trajectory():
    jumps = simulate_climb(SETUP, _legs, START, 6)
    h0 = start_height(LEFT_LEG, ROBOT)
    path = simulate_trajectory(
        ROBOT.to_model(), ControlSchedule.of(LEFT_LEG, RIGHT_LEG), START, 6, start_height=h0 / ROBOT.leg_length
    )
    si = path.to_si(ROBOT)
    starts = [j.start for j in jumps] + [touchdown_after(SETUP, jumps[-1])]
    assert_array_equal([s.state for s in starts], path.section_states, err_msg="the same kernel, the same states")
    assert_allclose([s.time for s in starts], si.touchdown_times, rtol=RTOL_SUM, err_msg="touchdown times [s]")
    assert_allclose([j.rise for j in jumps], si.rises, rtol=RTOL_SUM, err_msg="rise per jump [m]")
    first = jumps[0].samples
    one = simulate_trajectory(
        ROBOT.to_model(), ControlSchedule.of(LEFT_LEG, RIGHT_LEG), START, 1, start_height=h0 / ROBOT.leg_length
    ).to_si(ROBOT)
    for name in ("time", "x", "y", "foot_x", "foot_y", "zeta"):
        assert_array_equal(getattr(first, name), getattr(one, name), err_msg=f"jump 0's {name}")
    # Right-wall jumps are the simulator's left-wall stance mirrored.
    second = jumps[1].samples
    assert np.all(second.x[second.phase == STANCE] > 0)


NOISE = NoiseModel(psi0_deg=1.0, zeta0=0.005, velocity=0.01, pitch_drift_deg=1.0, asymmetry_zeta0=0.01)


def _noisy(seed: int):
    return simulate_climb(SETUP, _legs, START, 8, NoiseSampler(NOISE, np.random.default_rng(seed)))


def test_seeded_noise_is_reproducible_and_moves_the_climb():
    once, again, other = _noisy(4), _noisy(4), _noisy(5)
    assert [j.start for j in once] == [j.start for j in again]
    assert [j.start.state for j in once] != [j.start.state for j in other]
    clean = simulate_climb(SETUP, _legs, START, 8)
    assert once[1].start.leg != clean[1].start.leg, "the noise reaches the legs"
    assert once[1].start.pitch != 0.0 and once[0].start.pitch == 0.0, "the pitch drifts from 0 at launch"
    assert once[1].start.leg.zeta0 > once[0].start.leg.zeta0, "the right leg carries the asymmetry"


def test_a_descending_climb_ends_at_the_floor():
    weak = LegControl.from_degrees(30, 0.99)
    jumps = simulate_climb(SETUP, lambda _wall: weak, (-0.93, -0.17), 100)
    assert all(j.rise < 0 for j in jumps[:-1]), "it descends"
    last = jumps[-1]
    assert last.end is ClimbEnd.FLOOR and len(jumps) < 100
    y = np.concatenate([j.samples.y for j in jumps])
    assert y.min() >= FLOOR, "no sample below the floor"
    assert last.samples.y[-1] == FLOOR, "the last sample is where the body meets the floor"
    with pytest.raises(ValueError, match="floor"):
        touchdown_after(SETUP, last)


def test_a_climb_with_a_top_ends_at_the_jump_landing_above_it():
    climbing = LegControl.from_degrees(30, 0.90)
    free = simulate_climb(SETUP, lambda _wall: climbing, (-0.93, -0.17), 40)
    heights = [j.start.body_height for j in free]
    top = 0.5 * (heights[5] + heights[6])  # between touchdowns 5 and 6
    jumps = simulate_climb(dataclasses.replace(SETUP, top=top), lambda _wall: climbing, (-0.93, -0.17), 40)
    assert len(jumps) == 6 and jumps[-1].end is ClimbEnd.TOP and jumps[-1].arrival is None
    assert [j.start.body_height for j in jumps] == heights[:6], "the same climb up to the top"
    assert all(j.end is None for j in free), "no top: it climbs on"
    with pytest.raises(ValueError, match="top"):
        touchdown_after(SETUP, jumps[-1])


def test_a_failing_jump_ends_the_climb_with_its_failure():
    steep = LegControl.from_degrees(70, 0.9)  # outside the friction cone (mu = 2: 63.4°)
    jumps = simulate_climb(SETUP, lambda _wall: steep, START, 5)
    assert len(jumps) == 1 and jumps[0].end is Failure.SLIP and math.isnan(jumps[0].rise)
    assert stance(SETUP, jumps[0].start).end is Failure.SLIP


def test_a_next_leg_that_would_reach_the_other_wall_at_liftoff_can_be_replanned():
    """``no_flight`` is decided at lift-off by the next leg (here: too long for a narrow chute), so
    reading another leg there gives a jump again; a failure in the stance itself stays."""
    narrow = ClimbSetup(dataclasses.replace(ROBOT, wall_distance=1.4 * ROBOT.leg_length))
    start = launch(narrow, LegControl.from_degrees(30, 0.9), (-0.93, -0.2))
    blocked = jump(narrow, start, NextLeg(LegControl.from_degrees(30, 0.9)))
    assert blocked.end is Failure.NO_FLIGHT and len(blocked.flight) == 0
    freed = replan(narrow, blocked, NextLeg(LegControl.from_degrees(60, 0.5)))
    assert freed.end is None and len(freed.flight) > 0
    assert_array_equal(freed.stance.y, blocked.stance.y)
