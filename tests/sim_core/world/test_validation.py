"""A world's rules (sim_core/world/validation.py, docs/model.md §8): each broken one is named by side,
point or segment, and rule; the crossing check is exact at the vertex heights of both sides."""

import math

import numpy as np
import pytest

from sim_core.model.errors import ParameterError
from sim_core.world.validation import MAX_SEGMENTS, check_sides_apart, check_world
from sim_core.world.world import Side, World, parallel


def _world(left_points, right_points=((1.0, 0.0), (1.0, 1.0)), left_mu=None, right_mu=None) -> World:
    left, right = np.array(left_points, dtype=float), np.array(right_points, dtype=float)
    left_mu = np.full(len(left) - 1, math.nan) if left_mu is None else np.array(left_mu, dtype=float)
    right_mu = np.full(len(right) - 1, math.nan) if right_mu is None else np.array(right_mu, dtype=float)
    return World(Side(left, left_mu), Side(right, right_mu))


def _error(world: World) -> ParameterError:
    with pytest.raises(ParameterError) as raised:
        check_world(world)
    return raised.value


def test_a_valid_world_is_returned_as_is():
    world = parallel(2.42)
    assert check_world(world) is world
    with_every_friction = _world([(-1, 0), (-1, 1), (-1.2, 2), (-1, 3)], left_mu=[0.0, math.inf, math.nan])
    assert check_world(with_every_friction) is with_every_friction


@pytest.mark.parametrize(
    ("points", "field", "message"),
    [
        ([(-1, 0)], "left.points", "must have 2 to 257 points (1 to MAX_SEGMENTS = 256 segments), got 1"),
        ([(-1, 0), (math.nan, 1)], "left.points[1]", "x must be a finite number, got nan"),
        ([(-1, 0), (-1, math.inf)], "left.points[1]", "y must be a finite number, got inf"),
        ([(-1, 0), (-1, 0.9), (-1, 0.8)], "left.points[2]", "y must increase strictly bottom to top: 0.8 after 0.9"),
        ([(-1, 0), (-1, 1), (-1.5, 1)], "left.points[2]", "y must increase strictly bottom to top: 1.0 after 1.0"),
    ],
)
def test_each_points_rule_names_the_point(points, field, message):
    error = _error(_world(points))
    assert (error.field, error.message) == (field, message)


def test_too_many_segments_says_the_bound():
    y = np.arange(MAX_SEGMENTS + 2, dtype=float)
    error = _error(_world(np.column_stack((np.full_like(y, -1.0), y))))
    assert error.field == "left.points" and f"MAX_SEGMENTS = {MAX_SEGMENTS}" in error.message
    assert error.message.endswith(f"got {MAX_SEGMENTS + 2}")
    y = y[:-1]
    assert check_world(_world(np.column_stack((np.full_like(y, -1.0), y)))).left.segments == MAX_SEGMENTS


@pytest.mark.parametrize(
    ("right_mu", "field", "message"),
    [
        ([0.5, 1.0], "right.mu", "must have one entry per segment (1), got 2"),
        ([-1.0], "right.mu[0]", 'must be >= 0, null or "inf", got -1.0'),
        ([-math.inf], "right.mu[0]", 'must be >= 0, null or "inf", got -inf'),
    ],
)
def test_each_friction_rule_names_the_segment(right_mu, field, message):
    error = _error(_world([(-1, 0), (-1, 1)], right_mu=right_mu))
    assert (error.field, error.message) == (field, message)


def test_sides_that_touch_at_a_vertex_of_the_right_side_are_refused_there():
    # The left side is straight; the right side bends in to touch it at y = 1 only.
    error = _error(_world([(-1, 0), (1, 2)], right_points=[(1, 0), (0, 1), (1, 2)]))
    assert error.field == "right.points[1]"
    assert error.message.startswith("the sides must not cross or touch: at y = 1.0 the left side is at x = 0.0")


def test_sides_that_cross_are_refused_at_the_lowest_vertex_beyond():
    error = _error(_world([(-1, 0), (-1, 1), (2, 2)], right_points=[(1, 0), (1, 3)]))
    assert (error.field, error.message.split(":")[0]) == ("left.points[2]", "the sides must not cross or touch")
    assert "at y = 2.0 the left side is at x = 2.0, the right side at x = 1.0" in error.message


def test_the_vertical_continuations_count():
    # The right side ends at y = 1 and goes on vertically at x = 0.5; the left side reaches x = 0.5 at y = 3.
    error = _error(_world([(-1, 0), (-1, 1), (0.5, 3)], right_points=[(1, 0), (0.5, 1)]))
    assert error.field == "left.points[2]" and "at y = 3.0" in error.message
    assert check_world(_world([(-1, 0), (-1, 1), (0.49, 3)], right_points=[(1, 0), (0.5, 1)]))


def test_checking_the_vertex_heights_is_exact():
    """Against a dense sampling of both polylines: the check refuses exactly the pairs whose
    sides come within zero of each other somewhere."""
    rng = np.random.default_rng(5)
    for _ in range(200):
        left = np.column_stack((rng.uniform(-1.5, 0.3, 4), np.cumsum(rng.uniform(0.1, 1, 4))))
        right = np.column_stack((rng.uniform(-0.3, 1.5, 3), np.cumsum(rng.uniform(0.1, 1.3, 3))))
        heights = np.linspace(-1, 6, 20001)
        heights = np.union1d(heights, np.union1d(left[:, 1], right[:, 1]))
        apart = np.all(np.interp(heights, left[:, 1], left[:, 0]) < np.interp(heights, right[:, 1], right[:, 0]))
        try:
            check_sides_apart(left, right)
            refused = False
        except ParameterError:
            refused = True
        assert refused == (not apart)
