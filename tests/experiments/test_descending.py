"""The paper's stable descending period-1 gaits (experiments/descending.py): at psi0 30° the gait
is already unstable where it starts to descend, at 35° it descends stably just past jumping in
place, at 45° it is flip-unstable (an eigenvalue below -1); the claim states where it holds."""

from __future__ import annotations

import pytest

from experiments.descending import DescendingRow, descending_claim, descending_gaits, stable_psi0_range
from sim_core import get_preset

GUESS = (-0.94, 0.6)  # near the gait at psi0 30°, zeta0 0.80 (as Fig. 8)


@pytest.fixture(scope="module")
def rows():
    return descending_gaits(get_preset("paper").to_model(), [30.0, 35.0, 45.0], guess=GUESS)


def test_descending_gaits_are_stable_only_at_the_middle_angle(rows):
    at_30, at_35, at_45 = rows
    assert not at_30.stable and at_30.first_eigenvalue > 1.0, "descends, but unstable"
    assert at_35.stable and at_35.first_eigenvalue < 1.0
    assert at_35.in_place_zeta0 < at_35.stable_up_to < at_35.in_place_zeta0 + 0.03
    assert at_35.steepest_climb < 0.0, "a stable gait that loses height every jump"
    assert not at_45.stable and at_45.first_eigenvalue > 1.1
    assert stable_psi0_range(rows) == (35.0, 35.0)


def test_the_claim_states_the_range_where_it_holds(rows):
    claim = descending_claim(rows)
    assert claim.agrees is True
    assert claim.ours.startswith("only at psi0 35° (3 angles scanned over psi0 30–45°)")


def test_no_stable_descending_gait_disagrees_with_the_paper():
    unstable = DescendingRow(30.0, 0.9637, 1.0016, None, None)
    claim = descending_claim([unstable, unstable])
    assert claim.agrees is False and claim.ours.startswith("none at the 2 angles scanned over psi0 30°")
