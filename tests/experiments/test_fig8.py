"""Paper Fig. 8 (experiments/fig8.py): the period-1 gait over zeta0 — stability falling with
retraction, the zeta0 of jumping in place, basin areas on one window — and the basins drawn on one
colour scale, with the cells undecided at the jump limit in their own colour.

A sweep of 4 zeta0 values with coarse basins keeps it quick; the full configuration's claims are
checked by tests/experiments/test_reproduce.py (slow).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from experiments import fig8
from experiments.manifest import json_safe
from sim_core import get_preset
from sim_core.basins.grid import DEFAULT_BASIN_WINDOW

ROBOT = get_preset("paper")
CONFIG = fig8.Config(
    steps=4,
    basin_grid=8,
    basin_jumps=60,
    basin_jump_limit=240,
    shown_basins=(0.84, 0.94),
    shown_grid=10,
    descending_psi0_steps=3,
)


@pytest.fixture(scope="module")
def result():
    return fig8.run(ROBOT, CONFIG)


def test_more_retraction_is_more_stable_and_climbs_faster(result):
    sweep = result.sweep
    np.testing.assert_allclose(sweep.zeta0, np.linspace(*CONFIG.zeta0_range, CONFIG.steps))
    assert np.all(np.diff(sweep.max_abs_eigenvalue) > 0), "max |λ| rises with zeta0"
    assert np.all(np.diff(sweep.climb_per_jump) < 0), "the climb falls with zeta0"
    assert all(claim.agrees for claim in fig8.claims(result)), fig8.claims(result)


def test_the_gait_jumps_in_place_where_its_climb_changes_sign(result):
    sweep = result.sweep
    (in_place,) = sweep.in_place_zeta0
    assert CONFIG.zeta0_range[0] < in_place < CONFIG.zeta0_range[1]
    assert np.all(sweep.climb_per_jump[sweep.zeta0 < in_place] > 0)
    assert np.all(sweep.climb_per_jump[sweep.zeta0 > in_place] < 0)


def test_the_basins_are_measured_on_one_window_and_hold_their_gait(result):
    assert (result.window.xdot_range, result.window.ydot_range) == DEFAULT_BASIN_WINDOW
    assert result.window.cells == CONFIG.basin_grid
    (zeta0, basin), _ = result.shown
    assert zeta0 == 0.84 and basin.grid.cells == CONFIG.shown_grid
    assert basin.area > 0
    column = np.argmin(np.abs(basin.grid.xdot - basin.gait.state[0]))
    row = np.argmin(np.abs(basin.grid.ydot - basin.gait.state[1]))
    assert basin.mask[row, column], "the cell nearest the fixed point converges to it"


def test_its_table_has_a_row_per_zeta0_and_the_data_is_strict_json(result):
    table = fig8.table(result)
    lengths = {name: len(column) for name, column in table.items()}
    assert {lengths[name] for name in lengths if not name.startswith("descending_")} == {CONFIG.steps}
    assert {lengths[name] for name in lengths if name.startswith("descending_")} == {CONFIG.descending_psi0_steps}
    assert np.all(np.diff(table["energy_mgl0"]) < 0), "less retraction stores less energy"
    np.testing.assert_array_equal(table["basin_area_gl0"], result.sweep.basin_area)
    data = json.loads(json.dumps(json_safe(fig8.data(result)), allow_nan=False))
    assert data["shown_basins"][0]["zeta0"] == 0.84


def test_the_basins_are_continued_up_to_the_limit(result):
    for _, basin in result.shown:
        assert basin.max_jumps == CONFIG.basin_jumps and basin.jump_limit == CONFIG.basin_jump_limit
        assert basin.jumps_run.max() <= CONFIG.basin_jump_limit
        running = basin.undecided & ~basin.falling  # a falling cell stops once it falls
        assert (basin.jumps_run[running] == CONFIG.basin_jump_limit).all()
    assert result.sweep.basin_jump_limit == CONFIG.basin_jump_limit
    _, (_, near_in_place) = result.shown
    first, *_, last = near_in_place.rounds()
    assert last["converged"] > first["converged"], "at zeta0 0.94 the first cap cuts the basin short"


def test_the_figure_shows_the_basins_on_one_scale_and_states_the_limit(result):
    figure = fig8.plot(result)
    try:
        titles = [ax.get_title() for ax in figure.axes if ax.get_visible()]
        assert sum(title.startswith("Basin at zeta0 = 0.84") for title in titles) == 1
        assert sum(title.startswith("Basin at zeta0 = 0.94") for title in titles) == 1
        assert not figure.axes[5].get_visible(), "3 places for basins, 2 shown"
        colour_bars = [ax for ax in figure.axes if ax.get_label() == "<colorbar>"]
        assert len(colour_bars) == 1, "one colour bar for every basin"
        norms = {
            (image.norm.vmin, image.norm.vmax) for ax in figure.axes for image in ax.images if image.norm.vmin >= 1
        }
        assert len(norms) == 1, "one colour scale across the panels"
        (legend,) = figure.legends
        labels = [text.get_text() for text in legend.get_texts()]
        assert f"undecided at the {CONFIG.basin_jump_limit}-jump limit or falling" in labels
        assert any(label.startswith("fails: ") for label in labels)
        suptitle = figure.get_suptitle()
        assert f"{CONFIG.basin_jumps} jumps" in suptitle and f"up to {CONFIG.basin_jump_limit} jumps" in suptitle
    finally:
        figure.clf()


def test_the_notes_count_the_undecided_cells(result):
    notes = fig8.notes(result)
    assert any(f"up to {CONFIG.basin_jump_limit} jumps" in note for note in notes)
    assert sum("stay undecided" in note for note in notes) == len(result.shown)
