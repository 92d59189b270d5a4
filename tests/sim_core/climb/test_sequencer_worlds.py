"""The climb sequencer in a world (docs/model.md §8): on parallel walls the climb it always ran; in
a world the touchdowns of sim_core.world.climb, each stance's foot on its side; noise and the floor
as on parallel walls."""

import dataclasses

import numpy as np
import pytest

from sim_core import ControlSchedule, LegControl, get_preset
from sim_core.climb.records import ClimbEnd, ClimbSetup
from sim_core.climb.sequencer import simulate_climb
from sim_core.model.failures import Failure
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.trajectory import STANCE
from sim_core.model.walls import Wall
from sim_core.world.climb import climb_world
from sim_core.world.named import named_world
from sim_core.world.world import Side, World, parallel

ROBOT = get_preset("paper")
L0 = ROBOT.leg_length
LEFT_LEG, RIGHT_LEG = LegControl.from_degrees(30, 0.87), LegControl.from_degrees(30, 0.90)
START = (-1.0, 0.4)


def _legs(wall: Wall) -> LegControl:
    return LEFT_LEG if wall is Wall.LEFT else RIGHT_LEG


def test_on_parallel_walls_as_a_world_the_climb_is_the_one_it_always_was():
    walls = ClimbSetup(ROBOT, world=parallel(ROBOT.to_model().d_hat))
    ours, theirs = simulate_climb(walls, _legs, START, 12), simulate_climb(ClimbSetup(ROBOT), _legs, START, 12)
    assert len(ours) == len(theirs)
    for mine, old in zip(ours, theirs, strict=True):
        assert (mine.end, mine.liftoff) == (old.end, old.liftoff)
        assert mine.rise == pytest.approx(old.rise, abs=1e-10 * L0) and mine.arrival == pytest.approx(old.arrival)
        for name in ("time", "x", "y", "foot_x", "foot_y", "zeta"):
            assert getattr(mine.samples, name) == pytest.approx(getattr(old.samples, name), abs=1e-9), name


def test_in_a_world_the_touchdowns_are_the_worlds_climb_and_each_foot_stands_on_its_side():
    world = named_world("narrowing", ROBOT.to_model().d_hat)
    jumps = simulate_climb(ClimbSetup(ROBOT, world=world), _legs, START, 10)
    climb = climb_world(ROBOT.to_model(), world, ControlSchedule.of(LEFT_LEG, RIGHT_LEG), START, 10)
    assert all(jump.end is None for jump in jumps) and climb.failure is None
    heights = [jump.start.body_height / L0 for jump in jumps] + [None]
    for k, jump in enumerate(jumps):
        assert jump.start.body_x / L0 == pytest.approx(climb.states[k, 0], abs=1e-9)
        assert heights[k] == pytest.approx(climb.states[k, 1], abs=1e-9)
        stance = jump.samples.take(jump.samples.phase == STANCE)
        side = world.left if jump.wall is Wall.LEFT else world.right
        assert stance.foot_x / L0 == pytest.approx(side.x_at(stance.foot_y[0] / L0), abs=1e-12)
    assert jumps[-1].landing[0] / L0 == pytest.approx(climb.states[10, 0], abs=1e-9)


def test_noise_and_the_floor_as_on_parallel_walls():
    world = named_world("widening", ROBOT.to_model().d_hat)
    sampler = NoiseSampler(NoiseModel(), np.random.default_rng(3))
    noisy = simulate_climb(ClimbSetup(ROBOT, world=world), _legs, START, 8, sampler)
    assert len(noisy) >= 2 and noisy[1].start.leg != RIGHT_LEG, "the legs are drawn"
    descending = dataclasses.replace(LEFT_LEG, zeta0=0.97)
    falls = simulate_climb(ClimbSetup(ROBOT, world=world), lambda _wall: descending, (-1.0, 0.0), 60)
    assert falls[-1].end is ClimbEnd.FLOOR and falls[-1].samples.y.min() >= 0.0


def test_a_touchdown_on_a_side_with_no_grip_ends_the_climb_at_once():
    greasy = World(Side(np.array([[-1.21, -1.0], [-1.21, 9.0]]), np.array([0.0])), parallel(2.42).right, "greasy")
    jumps = simulate_climb(ClimbSetup(ROBOT, world=greasy), _legs, START, 5)
    assert len(jumps) == 1 and jumps[0].end is Failure.SLIP and len(jumps[0].samples) == 0
