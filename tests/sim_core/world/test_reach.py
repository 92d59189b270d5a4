"""The reach map: each cell is the climb `climb_world` makes with its controls, cut at the world's
top or the floor as the module says; chunks change nothing; too big a grid is refused."""

import numpy as np
import pytest

from sim_core import ControlSchedule
from sim_core.model.errors import ParameterError
from sim_core.world.climb import climb_world
from sim_core.world.named import named_world
from sim_core.world.reach import CAPPED, TOP, reach_map
from sim_core.world.world import Side, World


def _expected(paper, world, psi0_deg, zeta0, state, jumps):
    """One cell by hand: the climb's feet, then the first touchdown at the top or below the floor."""
    climb = climb_world(paper, world, ControlSchedule.from_degrees([(psi0_deg, zeta0)]), state, jumps)
    feet = climb.states[:, 1] - zeta0 * np.sin(np.radians(psi0_deg))
    for k in range(1, len(feet)):
        if climb.states[k, 1] < 0.0:
            return "floor", k - 1, feet[:k].max()
        if feet[k] >= world.top:
            return TOP, k, feet[: k + 1].max()
    ending = CAPPED if climb.failure is None else climb.failure.code
    return ending, len(feet) - 1, feet.max()


@pytest.mark.parametrize("name", ["narrowing", "widening", "staircase"])
def test_each_cell_is_its_own_climb_cut_at_the_top_or_the_floor(paper, name):
    world = named_world(name, paper.d_hat)
    psi0s, zeta0s, state = [18.0, 26.0, 31.0, 38.0, 47.0], [0.82, 0.88, 0.93, 0.96], (-1.1, 0.6)
    reach = reach_map(paper, world, psi0s, zeta0s, state, 30, chunk_rows=3)
    endings = reach.endings()
    for row, zeta0 in enumerate(zeta0s):
        for column, psi0 in enumerate(psi0s):
            ending, completed, highest = _expected(paper, world, psi0, zeta0, state, 30)
            assert (endings[row, column], reach.completed[row, column]) == (ending, completed), (psi0, zeta0)
            assert reach.highest[row, column] == pytest.approx(highest, abs=1e-12)
    assert sum(reach.outcomes().values()) == reach.status.size
    assert reach_map(paper, world, psi0s, zeta0s, state, 30, chunk_rows=1).to_dict() == reach.to_dict()


def test_a_chute_greasy_above_a_height_is_a_slip_map_above_it(paper):
    grip, greasy = np.array([[-1.21, 0.0], [-1.21, 1.0], [-1.21, 9.0]]), np.array([np.nan, 0.0])
    world = World(Side(grip, greasy), Side(grip * [-1, 1], greasy), "greasy above 1 l0")
    reach = reach_map(paper, world, [25.0, 30.0, 35.0], [0.86, 0.9], (-1.0, 0.5), 40)
    slipped = reach.endings() == "slip"
    assert slipped.sum() >= 4, "climbing gaits reach the greasy part"
    assert (reach.last[slipped] >= 1.0).all(), "the touchdown that slipped is the first one above 1 l0"


def test_a_grid_too_big_or_empty_is_refused_naming_it(paper):
    world = named_world("narrowing", paper.d_hat)
    with pytest.raises(ParameterError, match="jumps"):
        reach_map(paper, world, np.linspace(20, 40, 500), np.linspace(0.8, 0.95, 500), (-1.0, 0.5), 1000)
    with pytest.raises(ParameterError, match="grid"):
        reach_map(paper, world, [], [0.9], (-1.0, 0.5), 10)
    with pytest.raises(ParameterError, match="psi0_deg"):
        reach_map(paper, world, [95.0], [0.9], (-1.0, 0.5), 10)
