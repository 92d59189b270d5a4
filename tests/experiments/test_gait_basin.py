"""A gait's basin as one study (experiments/gait_basin.py), the orchestration behind ``parkour basin``
and the service's basin job."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.gait_basin import gait_basin
from sim_core.basins.basin import compute_basin
from sim_core.basins.grid import BasinGrid
from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import NoGaitFound, ParameterError
from sim_core.model.presets import START_GUESS, get_preset
from sim_core.section.gait_search import gait_of

MODEL = get_preset("paper").to_model()
SYMMETRIC = ControlSchedule.from_degrees([(30.0, 0.9)])


def test_default_window_is_the_gaits_state_plus_minus_its_half_width():
    basin = gait_basin(MODEL, SYMMETRIC, guess=START_GUESS, grid=8, max_jumps=20)
    gait = gait_of(MODEL, SYMMETRIC, guess=START_GUESS)
    expected = compute_basin(MODEL, SYMMETRIC, gait, BasinGrid.around(gait.state, 8), max_jumps=20)
    np.testing.assert_allclose(basin.gait.state, gait.state, atol=1e-9)
    assert basin.grid == expected.grid
    np.testing.assert_array_equal(basin.jumps_to_converge, expected.jumps_to_converge)
    np.testing.assert_array_equal(basin.failure, expected.failure)


def test_a_given_range_replaces_only_its_own_axis():
    basin = gait_basin(MODEL, SYMMETRIC, guess=START_GUESS, grid=6, max_jumps=20, xdot_range=(-1.5, -0.5))
    around = BasinGrid.around(basin.gait.state, 6)
    assert basin.grid.xdot_range == (-1.5, -0.5)
    assert basin.grid.ydot_range == around.ydot_range


def test_progress_is_reported_to_the_end():
    seen = []
    gait_basin(
        MODEL,
        SYMMETRIC,
        guess=START_GUESS,
        grid=6,
        max_jumps=20,
        progress=lambda done, total: seen.append((done, total)),
    )
    assert seen and seen[-1][0] == seen[-1][1]


@pytest.mark.parametrize(
    ("arguments", "field"),
    [({"grid": 1}, "grid"), ({"xdot_range": (-0.5, -1.5)}, "xdot_range"), ({"tolerance": -1.0}, "tolerance")],
)
def test_a_bad_spec_is_refused_before_the_gait_search(arguments, field):
    # Controls with no gait: a search would raise NoGaitFound; the spec's check must come first.
    no_gait = ControlSchedule.from_degrees([(5.0, 0.3)])
    with pytest.raises(ParameterError) as refused:
        gait_basin(MODEL, no_gait, **arguments)
    assert refused.value.field == field


def test_controls_without_a_gait_say_so():
    with pytest.raises(NoGaitFound):
        gait_basin(MODEL, ControlSchedule.from_degrees([(5.0, 0.3)]), grid=4)
