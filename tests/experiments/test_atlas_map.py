"""The gait atlas as a map (experiments/atlas_map.py): the climb per jump on a scale centred on
zero, with the in-place contour where the climb changes sign; the period of each cell's most
stable gait, blank where none was found, dots where a cell holds several; the files it writes.

The atlas here is made of hand-built gaits (a real one is computed in tests/sim_core/section/test_atlas.py
and drawn by ``parkour atlas --plot`` in tests/cli/test_atlas.py), so each cell's value is known.
"""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.contour import ContourSet
from matplotlib.image import AxesImage

from experiments.atlas_map import plot_atlas, save_atlas
from experiments.report import pyplot
from sim_core.section.atlas import GaitAtlas
from sim_core.section.fixed_points import FixedPoint


def gait(period: int, climb_per_jump: float, eigenvalue: float = 0.5) -> FixedPoint:
    return FixedPoint(
        state=np.array([-0.9, -0.2]),
        period=period,
        orbit=np.zeros((period, 2)),
        rises=np.full(period, climb_per_jump),
        jacobian=np.eye(2) * eigenvalue,
        eigenvalues=np.array([eigenvalue, eigenvalue], dtype=complex),
        residual=0.0,
    )


def atlas(cells) -> GaitAtlas:
    """Two rows (psi0 30°, 35°) by three columns (zeta0 0.88, 0.92, 0.96); ``cells`` row-major."""
    return GaitAtlas("psi0_deg", "zeta0", np.array([30.0, 35.0]), np.array([0.88, 0.92, 0.96]), tuple(cells))


CROSSING = atlas([(gait(1, 0.2),), (gait(2, 0.05), gait(1, 0.01)), (), (gait(1, 0.1),), (gait(4, -0.1),), ()])


@pytest.fixture
def drawn():
    figure = plot_atlas(CROSSING, "an atlas")
    yield figure
    pyplot().close(figure)


def images(ax) -> list[AxesImage]:
    return [artist for artist in ax.get_children() if isinstance(artist, AxesImage)]


def test_the_climb_is_drawn_on_a_scale_centred_on_zero_cells_centred_on_their_values(drawn):
    climb_axes, _period_axes, *_colorbars = drawn.axes
    (image,) = images(climb_axes)
    shown = image.get_array()
    np.testing.assert_allclose(np.ma.filled(shown, np.nan), CROSSING.climb_per_jump, equal_nan=True)
    assert (image.norm.vmin, image.norm.vcenter, image.norm.vmax) == (-0.2, 0.0, 0.2), "red climbs, blue descends"
    assert image.get_extent() == pytest.approx([0.86, 0.98, 27.5, 37.5])
    assert (climb_axes.get_xlabel(), climb_axes.get_ylabel()) == ("zeta0", "psi0_deg")
    assert drawn.get_suptitle() == "an atlas"


def test_the_in_place_contour_is_drawn_only_where_the_climb_changes_sign(drawn):
    assert any(isinstance(artist, ContourSet) for artist in drawn.axes[0].get_children())
    climbing = atlas([(gait(1, 0.2),), (gait(1, 0.1),), (), (gait(1, 0.1),), (gait(1, 0.05),), ()])
    figure = plot_atlas(climbing, "all climbing")
    try:
        assert not any(isinstance(artist, ContourSet) for artist in figure.axes[0].get_children())
    finally:
        pyplot().close(figure)


def test_the_period_map_is_blank_where_no_gait_and_marks_cells_with_several(drawn):
    period_axes = drawn.axes[1]
    (image,) = images(period_axes)
    shown = np.ma.filled(image.get_array(), np.nan)
    np.testing.assert_array_equal(shown, [[1.0, 2.0, np.nan], [1.0, 4.0, np.nan]])
    (dots,) = [line for line in period_axes.get_lines() if line.get_label() == "several gaits"]
    assert (dots.get_xdata().tolist(), dots.get_ydata().tolist()) == ([0.92], [30.0]), "the one cell with two gaits"
    colorbar = drawn.axes[-1]
    assert colorbar.get_ylabel() == "period [jumps]" and colorbar.get_yticks().tolist() == [1.0, 2.0, 4.0]


def test_an_atlas_without_any_gait_still_draws(tmp_path):
    empty = atlas([()] * 6)
    path = save_atlas(empty, tmp_path / "empty.png", "nothing found")
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_save_atlas_writes_the_map_as_png_or_svg(tmp_path):
    open_before = set(pyplot().get_fignums())
    png = save_atlas(CROSSING, tmp_path / "atlas.png", "an atlas")
    svg = save_atlas(CROSSING, tmp_path / "atlas.svg", "an atlas in SVG")
    assert png == tmp_path / "atlas.png" and png.read_bytes()[:4] == b"\x89PNG"
    assert "an atlas in SVG" in svg.read_text(), "text stays text"
    assert set(pyplot().get_fignums()) == open_before, "its figures are closed"
