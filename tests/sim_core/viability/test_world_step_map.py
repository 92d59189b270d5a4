"""Viability in a world: the centre-line step map on the engine — grip taken away only adds
failures (so never grows the kernel), a world whose centre line leaves the chute is refused, the
grid spans floor to top, and a step to the top is the chute climbed."""

import numpy as np
import pytest

from sim_core.model.errors import ParameterError
from sim_core.viability.engine import compute_viability
from sim_core.viability.world_step_map import world_grid, world_step_map
from sim_core.world.world import Side, World, parallel

GRIP_TO = 4.0  # [l0] the greasy world's grip ends here


def _greasy(d_hat: float) -> World:
    points = np.array([[-d_hat / 2, 0.0], [-d_hat / 2, GRIP_TO], [-d_hat / 2, 9.0]])
    mu = np.array([np.nan, 0.0])
    return World(Side(points, mu), Side(points * [-1, 1], mu), "greasy above 4 l0")


def test_taking_grip_away_only_adds_failures_so_never_grows_the_kernel(paper):
    walls = parallel(paper.d_hat, height=9.0)
    greasy = _greasy(paper.d_hat)
    grid = world_grid(walls, heights=10, states=14, actions=5, xdot_range=(-2.5, 2.5), ydot_range=(-3.0, 3.0))
    with_grip = compute_viability(world_step_map(paper, walls), grid)
    without = compute_viability(world_step_map(paper, greasy), grid)
    assert (without.failed | ~with_grip.failed).all(), "every pair that fails with grip fails without"
    both = ~without.failed & ~with_grip.failed
    assert np.array_equal(without.bins[both], with_grip.bins[both]), "where grip does not matter, the same step"
    assert without.failed.sum() > with_grip.failed.sum(), "the greasy part fails some pairs"
    assert not (without.kernel & ~with_grip.kernel).any() and not (without.viable_pairs & ~with_grip.viable_pairs).any()


def test_the_grid_spans_the_floor_to_the_top_and_a_world_off_centre_is_refused(paper):
    grid = world_grid(parallel(paper.d_hat, height=6.0), heights=7, states=4, actions=2)
    assert grid.state_axes[0][0] == 0.0 and grid.state_axes[0][-1] == 6.0 and len(grid.state_axes) == 3
    off_centre = World(Side(np.array([[0.2, 0.0], [0.2, 5.0]]), np.array([np.nan])),
                       Side(np.array([[2.6, 0.0], [2.6, 5.0]]), np.array([np.nan])), "off centre")  # fmt: skip
    with pytest.raises(ParameterError, match="centre line"):
        world_step_map(paper, off_centre)
    with pytest.raises(ParameterError, match="heights"):
        world_grid(off_centre, heights=1)


def test_a_step_to_the_top_is_the_chute_climbed(paper):
    walls = parallel(paper.d_hat, height=3.0)
    grid = world_grid(walls, heights=4, states=10, actions=4, xdot_range=(-2.5, 2.5), ydot_range=(-3.0, 3.0))
    states, actions = grid.states(), grid.actions()
    pairs = np.array([(s, a) for s in range(len(states)) for a in range(len(actions))])
    reached, failed, done = world_step_map(paper, walls)(states[pairs[:, 0]], actions[pairs[:, 1]])
    assert done.any() and not (done & failed).any()
    assert np.array_equal(done, ~failed & (reached[:, 0] >= 3.0))
    assert compute_viability(world_step_map(paper, walls), grid).kernel.any(), "climbing it is viable"
