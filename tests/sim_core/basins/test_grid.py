"""The basin's grid of start states: validation naming the field, the window around a gait,
the cells' order and area."""

import math
import subprocess
import sys

import numpy as np
import pytest

from sim_core import ParameterError
from sim_core.basins.grid import DEFAULT_HALF_WIDTH, BasinGrid


@pytest.mark.parametrize(
    ("build", "field"),
    [
        (lambda: BasinGrid((-2.0, -0.1), (-1.0, 1.0), 10**9), "grid"),
        (lambda: BasinGrid((-2.0, -0.1), (-1.0, 1.0), 1), "grid"),
        (lambda: BasinGrid((-0.1, -2.0), (-1.0, 1.0), 10), "xdot_range"),
        (lambda: BasinGrid((-1.0, 0.5), (-1.0, 1.0), 10), "xdot_range"),
        (lambda: BasinGrid((-2.0, -0.1), (1.0, 1.0), 10), "ydot_range"),
        (lambda: BasinGrid((-2.0, -0.1), (math.nan, 1.0), 10), "ydot_range"),
        (lambda: BasinGrid((-2.0, -0.1), (1.0,), 10), "ydot_range"),
    ],
)
def test_bad_grids_are_rejected(build, field):
    with pytest.raises(ParameterError, match=f"^{field}:"):
        build()


def test_states_run_along_xdot_first_then_ydot():
    grid = BasinGrid((-2.0, -1.0), (0.0, 1.0), 3)
    states = grid.states()
    assert states.shape == (9, 2)
    np.testing.assert_array_equal(states[:3, 0], grid.xdot)  # one row of the image: ydot fixed
    np.testing.assert_array_equal(states[::3, 1], grid.ydot)
    assert grid.cell_area == pytest.approx(0.5 * 0.5)


def test_the_window_around_a_state_stays_below_xdot_zero():
    grid = BasinGrid.around((-0.5, 0.2), 10)
    assert grid.xdot_range == (-0.5 - DEFAULT_HALF_WIDTH, -0.01 * DEFAULT_HALF_WIDTH)
    assert grid.ydot_range == (0.2 - DEFAULT_HALF_WIDTH, 0.2 + DEFAULT_HALF_WIDTH)
    with pytest.raises(ParameterError, match=r"^half_width:"):
        BasinGrid.around((-0.5, 0.2), 10, half_width=0.0)


def test_the_grid_loads_no_kernels():
    probe = "import sys, sim_core.basins.grid; print('numba' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False", "sim_core.basins.grid must stay light: the CLI reads its defaults"
