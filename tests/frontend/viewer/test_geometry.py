import numpy as np
import pytest
from numpy.testing import assert_allclose

from frontend.viewer.geometry import (
    LOADED,
    RELAXED,
    bow_leg,
    bow_legs,
    energy_color,
    energy_colors,
    idle_foot,
    polyline_segments,
    ruler_ticks,
    stored_energy,
)
from sim_core import LegControl, get_preset

ROBOT = get_preset("paper")
L0 = ROBOT.leg_length


def _sagitta(points):
    hip, foot = points[0], points[-1]
    chord = foot - hip
    relative = points - hip
    offsets = (chord[0] * relative[:, 1] - chord[1] * relative[:, 0]) / np.linalg.norm(chord)
    return np.abs(offsets).max()


def test_the_bow_runs_from_hip_to_foot_and_bends_more_when_compressed():
    relaxed = bow_leg((0.0, 0.0), (0.95 * L0, -0.1), L0)
    squeezed = bow_leg((0.0, 0.0), (0.7 * L0, -0.1), L0)
    assert np.allclose(relaxed[0], (0, 0)) and np.allclose(relaxed[-1], (0.95 * L0, -0.1))
    assert _sagitta(squeezed) > _sagitta(relaxed) > 0


def test_energy_colours_run_from_relaxed_to_loaded():
    assert energy_color(L0, ROBOT) == tuple(RELAXED)
    assert energy_color(0.5 * L0, ROBOT) == tuple(LOADED)
    assert stored_energy(0.9 * L0, ROBOT) == pytest.approx(0.5 * ROBOT.stiffness * (0.1 * L0) ** 2)
    assert stored_energy(1.2 * L0, ROBOT) == 0.0, "a leg longer than l0 stores nothing (it is free)"


def test_idle_foot_reaches_for_its_wall():
    leg = LegControl.from_degrees(30, 0.9)
    x, y = idle_foot((0.0, 1.0), leg, +1, ROBOT)
    assert x == pytest.approx(0.9 * L0 * np.cos(np.radians(30)))
    assert y == pytest.approx(1.0 - 0.9 * L0 * 0.5)
    assert idle_foot((0.0, 1.0), leg, -1, ROBOT)[0] == pytest.approx(-x)


def test_segments_and_ruler():
    segments = polyline_segments(np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 2.0]]))
    assert segments.shape == (2, 2, 3)
    assert segments[0, 1].tolist() == [1.0, 0.0, 2.0], "model y is scene z"
    ticks, majors = ruler_ticks(1.0)
    assert ticks.size == 21 and majors.tolist() == pytest.approx([0.0, 0.25, 0.5, 0.75, 1.0])


def test_many_legs_and_colours_at_once_are_each_ones():
    rng = np.random.default_rng(3)
    chords = np.column_stack([rng.uniform(-L0, L0, 20), rng.uniform(-L0, 0, 20)])
    chords[3] = 0.0  # a point: no bow
    bows = bow_legs(chords, L0)
    assert bows.shape == (20, 13, 2)
    for chord, bow in zip(chords, bows, strict=True):
        assert_allclose(bow, bow_leg((0.2, 0.5), (0.2 + chord[0], 0.5 + chord[1]), L0) - (0.2, 0.5), atol=1e-15)
    zetas = np.r_[np.linspace(0.5, 1.1, 13) * L0, np.nan]
    colours = energy_colors(zetas, ROBOT)
    assert colours.dtype == np.uint8
    assert [tuple(c) for c in colours] == [energy_color(z, ROBOT) for z in zetas[:-1]] + [tuple(RELAXED)]
    stacked = polyline_segments(np.stack([chords[:5], chords[5:10]]))
    assert stacked.shape == (2, 4, 2, 3)
    assert_allclose(stacked[1], polyline_segments(chords[5:10]))
