"""Whether a goal can be asked of a world: each refusal names the field, in metres when asked."""

import numpy as np
import pytest

from sim_core.model.errors import ParameterError
from sim_core.planning.goals import check_goal
from sim_core.world.random_world import random_world
from sim_core.world.world import Side, World


def test_a_goal_within_the_footholds_is_given_back_and_the_rest_refused():
    world = random_world(5)
    highest = max(side.points[1:, 1][side.mu != 0.0].max() for side in (world.left, world.right))
    assert check_goal(world, highest, 0.0) == (highest, 0.0)
    with pytest.raises(ParameterError, match=r"goal_height.*highest foothold"):
        check_goal(world, highest + 0.01, 0.0)
    with pytest.raises(ParameterError, match=r"goal_height.*above the start's foot"):
        check_goal(world, 0.5, 0.5)
    with pytest.raises(ParameterError, match=r"goal_height.*top \(1\.999 m\), got 2\.222 m"):
        check_goal(world, world.top + 1.0, 0.0, metres=0.223)
    assert check_goal(world, highest + 0.01, 0.0, footholds=False)[0] == highest + 0.01


def test_a_world_without_a_foothold_is_refused_naming_the_world():
    bare = Side(np.array([[-1.2, 0.0], [-1.2, 9.0]]), np.array([0.0]))
    with pytest.raises(ParameterError, match=r"world.*lab has no foothold"):
        check_goal(World(bare, Side(np.array([[1.2, 0.0], [1.2, 9.0]]), np.array([0.0]))), 1.0, 0.0, name="lab")
