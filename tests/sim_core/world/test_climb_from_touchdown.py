"""A climb in a world from a touchdown seen on either side (a tracked robot's first), read as the
Poincaré map's orbit: from the left side it is ``climb_world``'s climb, from the right the climb of
the mirrored world, and on parallel walls the map's own states and rises — the two models tied."""

import numpy as np
import pytest

from sim_core import ControlSchedule, iterate_map
from sim_core.model.errors import ParameterError
from sim_core.world.climb import climb_from_touchdown, climb_world, section_orbit
from sim_core.world.geometry import LEFT, RIGHT
from sim_core.world.named import named_world
from sim_core.world.world import Side, World

GAIT = ControlSchedule.from_degrees([(30, 0.87), (30, 0.9)])
TIGHT = 1e-9


def mirrored(world: World) -> World:
    """``world`` seen from behind: ``x -> -x``, its left side now the right and the right the left."""
    flip = np.array([-1.0, 1.0])
    return World(Side(world.right.points * flip, world.right.mu), Side(world.left.points * flip, world.left.mu))


def lopsided(d_hat: float) -> World:
    """An asymmetric chute: the narrowing world's left side beside the widening world's right."""
    return World(named_world("narrowing", d_hat).left, named_world("widening", d_hat).right, "lopsided")


def test_from_the_left_side_it_is_climb_world_s_climb(paper):
    world = named_world("staircase", paper.d_hat)
    for state, foot_y in (((-1.0, 0.5), 0.0), ((-0.8, -0.15), 1.3)):
        expected = climb_world(paper, world, GAIT, state, 8, foot_y=foot_y)
        ours = climb_from_touchdown(paper, world, GAIT, state, 8, side=LEFT, foot_y=foot_y)
        assert np.array_equal(ours.states, expected.states, equal_nan=True)
        assert np.array_equal(ours.sides, expected.sides) and np.array_equal(ours.segments, expected.segments)
        assert (ours.failure, ours.failed_jump) == (expected.failure, expected.failed_jump)


@pytest.mark.parametrize("name", ["lopsided", "staircase"])
def test_from_the_right_side_it_is_the_mirrored_world_s_climb(paper, name):
    world = lopsided(paper.d_hat) if name == "lopsided" else named_world(name, paper.d_hat)
    state, foot_y = (-0.9, 0.3), 0.8
    left = climb_world(paper, world, GAIT, state, 10, foot_y=foot_y)
    right = climb_from_touchdown(paper, mirrored(world), GAIT, state, 10, side=RIGHT, foot_y=foot_y)
    assert left.states.shape[0] >= 3, "a climb of a few jumps at least"
    assert right.sides[0] == RIGHT and np.array_equal(right.sides, 1 - left.sides)
    assert np.array_equal(right.segments, left.segments)
    assert right.states == pytest.approx(left.states * [-1.0, 1.0, -1.0, 1.0], abs=TIGHT)
    assert (right.failure, right.failed_jump) == (left.failure, left.failed_jump)
    ours, theirs = section_orbit(right, GAIT), section_orbit(left, GAIT)
    assert ours.states == pytest.approx(theirs.states, abs=TIGHT) and ours.rises == pytest.approx(
        theirs.rises, abs=TIGHT
    )


@pytest.mark.parametrize("side", [LEFT, RIGHT])
def test_on_parallel_walls_the_section_orbit_is_the_map_s(paper, side):
    """The hidden truth that ties both models: states and rises as iterate_map's, from either side
    and any height of the first foot."""
    world = named_world("parallel", paper.d_hat)
    for state, foot_y in (((-1.0, 0.5), 0.0), ((-0.815, -0.158), 2.7)):
        orbit = section_orbit(climb_from_touchdown(paper, world, GAIT, state, 7, side=side, foot_y=foot_y), GAIT)
        expected = iterate_map(paper, GAIT, state, 7)
        assert orbit.failure is None and orbit.states.shape == expected.states.shape
        assert np.abs(orbit.states - expected.states).max() < TIGHT
        assert np.abs(orbit.rises - expected.rises).max() < TIGHT


@pytest.mark.parametrize("state", [(-0.1, -2.0), (-2.0, 3.0), (-3.0, -3.0)])
def test_a_failing_climb_says_it_as_the_map_does(paper, state):
    world = named_world("parallel", paper.d_hat)
    orbit = section_orbit(climb_from_touchdown(paper, world, GAIT, state, 5, side=RIGHT, foot_y=0.4), GAIT)
    expected = iterate_map(paper, GAIT, state, 5)
    assert expected.failure is not None
    ours, theirs = orbit.to_dict(), expected.to_dict()
    assert ours["failure"] == theirs["failure"]
    assert np.array(ours["states"]) == pytest.approx(np.array(theirs["states"]), abs=TIGHT)
    assert ours["rises"] == pytest.approx(theirs["rises"], abs=TIGHT)


def test_a_side_is_left_or_right(paper):
    with pytest.raises(ParameterError, match="side"):
        climb_from_touchdown(paper, named_world("parallel", paper.d_hat), GAIT, (-1.0, 0.5), 2, side=2, foot_y=0.0)
