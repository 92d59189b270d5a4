"""sim_core/viability/grid.py: the grid's axes and the section's default grid, and what they refuse."""

import numpy as np
import pytest

from sim_core.model.validation import ParameterError
from sim_core.viability.grid import ViabilityGrid, degrees_of, section_grid


def test_the_grid_with_a_pitch_axis_is_symmetric_and_actions_read_in_degrees():
    grid = section_grid(states=4, actions=3, pitch_nodes=5, pitch_deg=2.0)
    pitch = grid.state_axes[2]
    np.testing.assert_allclose(pitch, -pitch[::-1], atol=1e-15)
    assert grid.shape == (4, 4, 5, 3, 3)
    np.testing.assert_allclose(degrees_of(grid.actions())[:, 0].min(), 15.0)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"states": 1}, "states: must be an integer >= 2"),
        ({"actions": 2.5}, "actions: must be an integer >= 2"),
        ({"xdot_range": (-1.0, 2.0)}, "xdot_range: must be in"),
        ({"zeta0_range": (0.9, 0.8)}, "zeta0_range: must be a non-empty interval with low < high within"),
        ({"pitch_nodes": 3}, "pitch_deg: must be in"),
        ({"pitch_nodes": 3, "pitch_deg": 45.0}, "pitch_deg: must be in"),
        ({"states": 3000, "actions": 100}, "grid: must hold at most"),
    ],
)
def test_a_bad_grid_option_is_named(options, message):
    with pytest.raises(ParameterError, match=message):
        section_grid(**options)


@pytest.mark.parametrize(
    ("state_axes", "action_axes", "message"),
    [
        ((np.array([0.0, 0.0, 1.0]),), (np.arange(2.0),), r"state_axes\[0\]: must be finite and strictly increasing"),
        ((np.array([1.0]),), (np.arange(2.0),), r"state_axes\[0\]: must be a 1-D axis of at least 2 nodes"),
        ((np.arange(3.0),), (np.array([]),), r"action_axes\[0\]: must be a 1-D axis of at least 1 nodes"),
        ((), (np.arange(2.0),), "state_axes: must hold 1 to 4 axes"),
        ((np.arange(8000.0), np.arange(8000.0)), (np.arange(2.0),), "grid: must hold at most 50,000,000"),
    ],
)
def test_a_bad_grid_is_refused_naming_the_axis(state_axes, action_axes, message):
    with pytest.raises(ParameterError, match=message):
        ViabilityGrid(state_axes, action_axes)
