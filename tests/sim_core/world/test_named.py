"""Named worlds (sim_core/world/named.py): each valid and as described, wide enough for the robot's
legs, and an unknown name answered with the known ones."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core.model.errors import ParameterError
from sim_core.model.presets import get_preset
from sim_core.world.files import save_world, world_from_document, world_to_document
from sim_core.world.named import (
    CHUTE_HEIGHT,
    NAMED_WORLDS,
    PAPER_D_HAT,
    STEP_INCLINE_DEG,
    named_world,
    resolve_world,
)
from sim_core.world.validation import check_world
from sim_core.world.world import inclinations

# The widest a pair of legs reaches across at touchdown, zeta0 cos psi0 each, for zeta0 <= 0.95 and
# psi0 >= 20° (the controls in use): a chute narrower than that leaves the body no room to fly.
TWO_LEGS = 2 * 0.95 * math.cos(math.radians(20))


def _widths(world, heights):
    return np.array([world.right.x_at(y) - world.left.x_at(y) for y in heights])


def test_the_paper_chute_is_2_m_of_its_l0():
    assert math.isclose(PAPER_D_HAT, 2.42, rel_tol=1e-12)
    assert CHUTE_HEIGHT * get_preset("paper").leg_length == pytest.approx(2.0, rel=1e-12)


@pytest.mark.parametrize("name", list(NAMED_WORLDS))
def test_every_named_world_is_valid_named_and_wide_enough(name):
    world = named_world(name, PAPER_D_HAT)
    assert check_world(world) is world and world.name == name
    heights = np.linspace(0, CHUTE_HEIGHT, 1001)
    assert _widths(world, heights).min() > TWO_LEGS, "the robot's legs fit between the sides"
    assert max(world.left.points[-1, 1], world.right.points[-1, 1]) == pytest.approx(CHUTE_HEIGHT)
    assert NAMED_WORLDS[name].description
    assert_allclose(world_from_document(world_to_document(world)).left.points, world.left.points)


def test_parallel_is_the_models_chute():
    world = named_world("parallel", 3.0)
    assert_allclose(_widths(world, [-1.0, 0.0, 5.0, 20.0]), 3.0)
    assert np.isnan(world.left.mu).all() and np.isnan(world.right.mu).all()


def test_narrowing_and_widening_taper_as_described():
    narrowing, widening = named_world("narrowing", PAPER_D_HAT), named_world("widening", PAPER_D_HAT)
    assert_allclose(_widths(narrowing, [0.0, CHUTE_HEIGHT]), [PAPER_D_HAT, 0.75 * PAPER_D_HAT])
    assert_allclose(_widths(widening, [0.0, CHUTE_HEIGHT]), [PAPER_D_HAT, 1.3 * PAPER_D_HAT])
    assert inclinations(narrowing.left.points, "left")[0] < 0 < inclinations(widening.right.points, "right")[0]


def test_the_staircase_has_upward_steps_with_grip_and_no_grip_between():
    world = named_world("staircase", PAPER_D_HAT)
    for name in ("left", "right"):
        side = world.side(name)
        betas = np.degrees(inclinations(side.points, name))
        gripping = np.isnan(side.mu)  # the model's mu
        assert gripping.sum() >= 10 and np.all(side.mu[~gripping] == 0)
        assert_allclose(betas[gripping], STEP_INCLINE_DEG, err_msg=name)
        assert 15 <= STEP_INCLINE_DEG <= 30
        assert np.all(np.diff(side.points[:, 1]) > 0)
    assert world.left.mu[0] != 0, "the climb's first foot, at the floor on the left, has a step"
    first_steps = [
        world.side(name).points[np.flatnonzero(np.isnan(world.side(name).mu))[0], 1] for name in ("left", "right")
    ]
    assert first_steps[0] < first_steps[1], "the right side's steps are offset upward"


def test_an_unknown_name_lists_the_known_ones():
    with pytest.raises(ParameterError) as raised:
        named_world("maze", PAPER_D_HAT)
    assert raised.value.field == "world"
    assert raised.value.message == "unknown world 'maze'; named worlds: parallel, narrowing, widening, staircase"


def test_a_width_too_narrow_for_the_world_names_d_hat():
    with pytest.raises(ParameterError) as raised:
        named_world("staircase", 0.05)
    assert raised.value.field == "d_hat" and "too narrow for the staircase world" in raised.value.message
    with pytest.raises(ParameterError, match=r"d_hat: must be in \(0, inf\)"):
        named_world("parallel", -1.0)


def test_resolve_a_name_or_a_file(tmp_path):
    world, description = resolve_world("narrowing", 2.0)
    assert world.name == "narrowing" and description == NAMED_WORLDS["narrowing"].description
    path = tmp_path / "mine.json"
    save_world(named_world("widening", 2.0), path, "m", 0.25, description="wider up")
    world, description = resolve_world(str(path), 9.0, l0_m=0.25)
    assert description == "wider up" and world.name == "widening"
    assert_allclose(_widths(world, [0.0]), [2.0])
    with pytest.raises(ParameterError, match="'maze' is neither a named world"):
        resolve_world("maze", 2.0)
