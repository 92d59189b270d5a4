"""A world's sides as the kernels read them: segments by height, the side's x, inclinations, and
the touchdown's closed form against a brute-force search along the flight."""

import math

import numpy as np
import pytest

from sim_core.world.geometry import first_crossing, pack, segment_at, side_x
from sim_core.world.world import Side, World, inclinations, parallel

UP = math.radians


def _world(left_points, right_points, left_mu=None, right_mu=None):
    left_points, right_points = np.asarray(left_points, float), np.asarray(right_points, float)
    left_mu = np.full(len(left_points) - 1, np.nan) if left_mu is None else np.asarray(left_mu, float)
    right_mu = np.full(len(right_points) - 1, np.nan) if right_mu is None else np.asarray(right_mu, float)
    return World(Side(left_points, left_mu), Side(right_points, right_mu))


def test_a_vertex_belongs_to_the_segment_above_and_the_ends_go_on_vertically():
    sides = pack(_world([[-1, 0], [-1.2, 1], [-1.1, 2]], [[1, 0], [1, 2]]), 2.0)
    assert [segment_at(sides, 0, y) for y in (-5.0, -1e-12, 0.0, 0.5, 1.0, 1.5, 2.0, 9.0)] == [-1, -1, 0, 0, 1, 1, 2, 2]
    assert side_x(sides, 0, -3.0) == -1.0 and side_x(sides, 0, 7.0) == -1.1
    assert side_x(sides, 0, 0.5) == pytest.approx(-1.1) and side_x(sides, 0, 1.5) == pytest.approx(-1.15)


def test_inclination_is_the_inward_normals_angle_in_the_sides_stance_frame():
    # A left side whose top leans away from the chute faces upward: beta > 0; one leaning in, beta < 0.
    away, inward = np.array([[-1.0, 0.0], [-2.0, 1.0]]), np.array([[-1.0, 0.0], [-0.5, 1.0]])
    assert inclinations(away, "left")[0] == pytest.approx(UP(45))
    assert inclinations(inward, "left")[0] == pytest.approx(-math.atan2(0.5, 1.0))
    # The right side's mirror image of a left side has the same inclinations in its own frame.
    assert inclinations(away * [-1, 1], "right")[0] == pytest.approx(UP(45))
    assert inclinations(np.array([[-1.0, 0.0], [-1.0, 3.0]]), "left")[0] == 0.0


def test_friction_left_open_is_the_models_and_the_continuations_have_it_with_no_incline():
    sides = pack(_world([[-1, 0], [-2, 1], [-2, 2]], [[1, 0], [1, 2]], left_mu=[np.nan, np.inf]), 0.7)
    assert sides.friction[0, :4].tolist() == [0.7, 0.7, math.inf, 0.7]
    assert sides.beta[0, 0] == 0.0 and sides.beta[0, 3] == 0.0 and sides.beta[0, 1] == pytest.approx(UP(45))


def _brute_force(world, side, mirror, start, velocity, step=1e-5):
    """The first time the foot's x reaches the side's, by stepping along the flight."""
    times = np.arange(0.0, 10.0, step)
    x = start[0] + velocity[0] * times
    y = start[1] + velocity[1] * times - 0.5 * times**2
    points = world.side(("left", "right")[side]).points
    gaps = x - mirror * np.interp(y, points[:, 1], points[:, 0])
    crossed = np.flatnonzero(gaps >= 0.0)
    return (times[crossed[0]], y[crossed[0]]) if crossed.size else (math.inf, math.nan)


@pytest.mark.parametrize("seed", range(6))
def test_the_touchdown_in_closed_form_is_the_first_crossing_a_search_finds(seed):
    rng = np.random.default_rng(seed)
    heights = np.sort(rng.uniform(-1.0, 6.0, 12))
    right = np.c_[1.2 + rng.uniform(-0.4, 0.4, 12), heights]
    world = _world([[-1.2, 0.0], [-1.2, 1.0]], right)
    sides = pack(world, 2.0)
    found = 0
    for _ in range(40):
        start = (rng.uniform(-1.0, 0.3), rng.uniform(-0.5, 3.0))
        velocity = (rng.uniform(0.2, 3.0), rng.uniform(-1.0, 3.0))
        t, segment = first_crossing(sides, 1, 1.0, *start, *velocity)
        expected, height = _brute_force(world, 1, 1.0, start, velocity)
        if math.isinf(expected):
            assert math.isinf(t) or t >= 10.0 - 1e-5
            continue
        found += 1
        assert t == pytest.approx(expected, abs=2e-5)
        assert segment == segment_at(sides, 1, height) or abs(height - heights).min() < 1e-4  # at a vertex: either
    assert found > 20


def test_a_tangent_touch_counts_and_a_miss_does_not():
    # A foot rising to its apex at y = 1 meets a ledge whose edge is exactly there
    sides = pack(_world([[-2, 0], [-2, 1]], [[1.0, 0.0], [0.5, 1.0], [1.5, 2.0]]), 2.0)
    t, segment = first_crossing(sides, 1, 1.0, 0.0, 0.5, 0.5, 1.0)  # reaches x = 0.5 at t = 1, y = 1.0
    assert t == pytest.approx(1.0) and segment == 1, "at the vertex: the segment above"
    never = pack(parallel(2.0), 2.0)
    assert math.isinf(first_crossing(never, 1, 1.0, 0.0, 0.0, -0.5, 1.0)[0]), "flying away meets nothing"
