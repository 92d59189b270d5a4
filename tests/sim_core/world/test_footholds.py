"""Footholds as geometry (sim_core/world/footholds.py): beta as docs/model.md §8 defines it, and a side
of footholds laid out with the lengths, inclinations, friction and gaps it was given."""

import itertools
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sim_core.world.footholds import NO_GRIP, foothold_side, holds_below
from sim_core.world.world import inclinations

ATOL = 1e-12


@pytest.mark.parametrize(
    ("step", "beta_deg"),
    [((0.0, 1.0), 0.0), ((-1.0, 1.0), 45.0), ((1.0, 1.0), -45.0), ((-1.0, math.sqrt(3)), 30.0)],
)
def test_beta_is_the_normals_angle_on_the_left_and_mirrored_on_the_right(step, beta_deg):
    """Left: a top leaning away from the chute (x decreasing upward) faces upward, beta > 0."""
    left = np.array([[-1.0, 0.0], [-1.0 + step[0], step[1]]])
    assert math.degrees(inclinations(left, "left")[0]) == pytest.approx(beta_deg, abs=ATOL)
    right = left * [-1.0, 1.0]
    assert math.degrees(inclinations(right, "right")[0]) == pytest.approx(beta_deg, abs=ATOL)


def test_beta_from_the_spec_formula():
    rng = np.random.default_rng(1)
    points = np.column_stack((rng.uniform(-2, -1, 6), np.cumsum(rng.uniform(0.1, 1, 6))))
    expected = []
    for a, b in itertools.pairwise(points):
        t = (b - a) / np.hypot(*(b - a))
        n = (t[1], -t[0])
        expected.append(math.atan2(n[1], n[0]))
    assert_allclose(inclinations(points, "left"), expected, atol=ATOL)


def test_a_side_of_footholds_has_what_it_was_given():
    lengths, betas = np.array([0.3, 0.2, 0.4]), np.radians([20.0, -10.0, 35.0])
    mu, gaps = np.array([1.5, math.inf, math.nan]), np.array([0.15, 0.3])
    for name, wall_x in (("left", -1.21), ("right", 1.21)):
        side = foothold_side(name, wall_x, lengths, betas, mu, gaps, start=0.2, top=3.0)
        assert_array_equal(side.points[0], [wall_x, 0.0]), "from the floor to the first foothold: no grip"
        assert_array_equal(side.points[-1], [wall_x, 3.0])
        assert_array_equal(side.mu, [NO_GRIP, 1.5, NO_GRIP, math.inf, NO_GRIP, math.nan, NO_GRIP])
        holds = side.points[1:-1]
        assert_allclose(inclinations(holds, name)[0::2], betas, atol=ATOL, err_msg=name)
        assert_allclose(np.hypot(*np.diff(holds, axis=0)[0::2].T), lengths, atol=ATOL)
        assert_allclose(np.diff(holds[:, 1])[1::2], gaps, atol=ATOL, err_msg="rise without grip")
        assert_allclose((holds[0::2, 0] + holds[1::2, 0]) / 2, wall_x, atol=ATOL, err_msg="centred on the wall")
        assert holds[0, 1] == 0.2 and np.all(np.diff(side.points[:, 1]) > 0)


def test_no_extra_segments_when_not_asked():
    side = foothold_side("left", -1.0, np.array([0.3]), np.array([0.2]), np.array([2.0]), np.array([]), top=0.1)
    assert side.points.shape == (2, 2) and side.points[0, 1] == 0.0 and side.mu.tolist() == [2.0]


def test_holds_below_counts_the_footholds_ending_under_a_height():
    lengths, betas, gaps = np.full(5, 0.5), np.zeros(5), np.full(5, 0.5)  # tops at 0.5, 1.5, 2.5, ...
    assert [holds_below(lengths, betas, gaps, h) for h in (0.4, 0.5, 1.49, 1.5, 9.0)] == [0, 1, 1, 2, 5]
    assert holds_below(lengths, betas, gaps, 1.5, start=0.1) == 1
