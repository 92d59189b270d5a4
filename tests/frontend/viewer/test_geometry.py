import numpy as np
import pytest

from frontend.viewer.geometry import (
    LOADED,
    RELAXED,
    bow_leg,
    energy_color,
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
