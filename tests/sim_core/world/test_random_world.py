"""Random footholds (sim_core/world/random_world.py): the same seed gives the same world and another
seed another; every world over 200 seeds keeps the rules and the drawn ranges; arguments out of
range are named."""

import math

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sim_core.model.errors import ParameterError
from sim_core.world.named import CHUTE_HEIGHT, PAPER_D_HAT
from sim_core.world.random_world import GAP, HOLD_LENGTH, INCLINE_DEG, MAX_HOLDS, MU, random_world
from sim_core.world.validation import check_world
from sim_core.world.world import inclinations

ATOL = 1e-9
SEEDS = range(200)


def _holds(world, name):
    """A side's footholds: (points from, points to, beta [deg], mu) of its gripping segments."""
    side = world.side(name)
    gripping = side.mu > 0
    betas = np.degrees(inclinations(side.points, name))
    return side.points[:-1][gripping], side.points[1:][gripping], betas[gripping], side.mu[gripping]


def test_the_same_seed_gives_the_same_world_and_another_seed_another():
    a, b, c = random_world(11), random_world(11), random_world(12)
    for name in ("left", "right"):
        assert_array_equal(a.side(name).points, b.side(name).points)
        assert_array_equal(a.side(name).mu, b.side(name).mu)
        assert a.side(name).points.shape != c.side(name).points.shape or not np.array_equal(
            a.side(name).points, c.side(name).points
        )
    assert a.name == "random-11"


def test_the_first_footholds_do_not_depend_on_how_many():
    few, many = random_world(4, holds=3), random_world(4, holds=9)
    assert_array_equal(few.left.points[:5], many.left.points[:5])
    assert_array_equal(few.right.mu[:5], many.right.mu[:5])


@pytest.mark.parametrize("seed", SEEDS)
def test_every_seed_gives_a_valid_world_within_its_ranges(seed):
    world = random_world(seed)
    assert check_world(world) is world
    for name in ("left", "right"):
        side = world.side(name)
        start, end, betas, mu = _holds(world, name)
        assert len(betas) >= 10, "2 m of footholds"
        assert np.all((INCLINE_DEG[0] - ATOL <= betas) & (betas <= INCLINE_DEG[1] + ATOL))
        assert np.all((MU[0] <= mu) & (mu <= MU[1]))
        lengths = np.hypot(*(end - start).T)
        assert np.all((HOLD_LENGTH[0] - ATOL <= lengths) & (lengths <= HOLD_LENGTH[1] + ATOL))
        gaps = start[1:, 1] - end[:-1, 1]
        assert np.all((GAP[0] - ATOL <= gaps) & (gaps <= GAP[1] + ATOL))
        assert start[0, 1] == 0.0, "a foothold at the floor"
        assert side.points[-1, 1] == pytest.approx(CHUTE_HEIGHT) and end[-1, 1] <= CHUTE_HEIGHT
        assert np.all(side.mu[side.mu <= 0] == 0)
        assert np.all(np.abs(np.abs(side.points[:, 0]) - PAPER_D_HAT / 2) <= HOLD_LENGTH[1] / 2)


def test_holds_asked_for_are_given_and_may_go_past_the_height():
    world = random_world(2, holds=5, height=1.0, gap=(0.3, 0.3), hold_length=(0.25, 0.25), incline_deg=(0, 0))
    assert len(_holds(world, "left")[2]) == 5 and world.left.points[-1, 1] == pytest.approx(5 * 0.25 + 4 * 0.3)
    one = random_world(2, height=0.01)
    assert len(_holds(one, "right")[2]) == 1, "at least one foothold"


def test_the_arguments_shape_the_world():
    world = random_world(3, incline_deg=(25, 25), mu=(0.5, 0.5), width=4.0, height=3.0)
    for name, wall_x in (("left", -2.0), ("right", 2.0)):
        start, end, betas, mu = _holds(world, name)
        assert np.allclose(betas, 25) and np.all(mu == 0.5)
        assert np.allclose((start[:, 0] + end[:, 0]) / 2, wall_x), "centred on the wall lines width apart"
    assert world.left.points[-1, 1] == pytest.approx(3.0)


@pytest.mark.parametrize(
    ("arguments", "field", "message"),
    [
        ({"seed": -1}, "seed", "must be an integer >= 0, got -1"),
        ({"seed": 1.5}, "seed", "must be an integer >= 0, got 1.5"),
        ({"holds": True}, "holds", "must be an integer, got True"),
        ({"holds": 0}, "holds", f"must be in [1, {MAX_HOLDS}] per side (MAX_HOLDS), got 0"),
        ({"holds": MAX_HOLDS + 1}, "holds", f"must be in [1, {MAX_HOLDS}] per side (MAX_HOLDS), got {MAX_HOLDS + 1}"),
        ({"incline_deg": (-90, 10)}, "incline_deg", "must be in (-80, 80), got -90"),
        ({"incline_deg": (30, 10)}, "incline_deg", "must be an interval (low, high) with low <= high, got (30, 10)"),
        ({"incline_deg": 10}, "incline_deg", "must be a pair (low, high), got 10"),
        ({"mu": (-0.5, 1)}, "mu", "must be in [0, inf), got -0.5"),
        ({"mu": (1, math.inf)}, "mu", "must be a finite number, got inf"),
        ({"gap": (0, 0.2)}, "gap", "must be in (0, inf), got 0"),
        ({"hold_length": (0.2, math.nan)}, "hold_length", "must be a finite number, got nan"),
        ({"height": 0}, "height", "must be in (0, inf), got 0"),
        (
            {"width": 0.3, "incline_deg": (-30, 30), "hold_length": (0.2, 0.8)},
            "width",
            "must be > 0.4 l0 so that footholds on the two sides cannot touch, got 0.3",
        ),
        (
            {"height": 1000.0},
            "height",
            f"1000 l0 fits more than MAX_HOLDS = {MAX_HOLDS} footholds per side; lower it or give holds",
        ),
    ],
)
def test_arguments_out_of_range_are_named(arguments, field, message):
    with pytest.raises(ParameterError) as raised:
        random_world(**{"seed": 0, **arguments})
    assert (raised.value.field, raised.value.message) == (field, message)


def test_a_fixed_interval_is_allowed():
    assert random_world(0, gap=(0.2, 0.2), mu=(0, 0), holds=2).left.mu.tolist() == [0.0, 0.0, 0.0, 0.0]
