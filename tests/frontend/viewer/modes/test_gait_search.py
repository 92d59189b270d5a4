"""Simulate mode's gait readout (frontend/viewer/modes/gait_search.py): the paper's gaits as presets
named by their controls, and the search for the gait of the sliders' controls, described in a line.
(The readout in a browser's view is tested in test_simulate.py.)"""

from __future__ import annotations

import re

import pytest

from frontend.viewer.modes.gait_search import DEFAULT_START, GAIT_PRESETS, find_gait
from frontend.viewer.simulated_climb import Controls
from sim_core import LegControl, get_preset
from sim_core.model.presets import PAPER_GAITS

ROBOT = get_preset("paper")
NUMBER = r"[-+]?\d+\.\d+"


def test_the_presets_are_the_papers_gaits_named_by_their_controls():
    assert list(GAIT_PRESETS) == [
        "period 1 · 30° · 0.90",
        "period 2 · 30°/30° · 0.87/0.90",
        "period 4 · 30°/35° · 0.90/0.9505",
    ], "zeta0 with two decimals at least, all of them when it has more"
    for (left, right), pairs in zip(GAIT_PRESETS.values(), PAPER_GAITS.values(), strict=True):
        assert (left, right) == (pairs[0], pairs[-1]), "a one-pair gait sets both legs"


@pytest.mark.parametrize(("name", "period"), [("period 1", 1), ("period 2", 2), ("period 4", 4)])
def test_each_presets_gait_is_found_stable_and_described(name, period):
    (left, right) = (LegControl.from_degrees(*pair) for pair in (PAPER_GAITS[name][0], PAPER_GAITS[name][-1]))
    gait, line = find_gait(Controls(left, right, ROBOT), DEFAULT_START)
    assert gait.period == period and gait.stable, line
    climb_cm = 100 * gait.climb_per_period / gait.period * ROBOT.leg_length
    assert line.startswith(f"period {period}, stable, max|λ| = {gait.max_abs_eigenvalue:.3f}, climbing ")
    assert f"{climb_cm:+.2f} cm/jump" in line, "the climb per jump in centimetres at the robot's size"
    assert re.search(rf"fixed point \({NUMBER}, {NUMBER}\)$", line)


def test_an_unstable_gait_is_named_unstable():
    weak = LegControl.from_degrees(30, 0.99)  # beyond jumping in place: period 1, descending, |λ| > 1
    gait, line = find_gait(Controls(weak, weak, ROBOT), DEFAULT_START)
    assert not gait.stable and "**unstable**" in line and " descending " in line


def test_controls_without_any_gait_say_so():
    steep = LegControl.from_degrees(80, 0.5)
    assert find_gait(Controls(steep, steep, ROBOT), DEFAULT_START) == (
        None,
        "none found (a grid search of period 1, 2 and 4 found no gait)",
    )
