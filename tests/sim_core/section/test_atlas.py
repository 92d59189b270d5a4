"""The gait atlas: finds the paper's gaits, only stable ones, and their periods."""

import numpy as np
import pytest

from sim_core import ControlSchedule, ParameterError, find_fixed_point
from sim_core.section.atlas import gait_atlas


def _symmetric(paper, psi0s, zeta0s):
    schedules = [ControlSchedule.from_degrees([(psi0, zeta0)]) for psi0 in psi0s for zeta0 in zeta0s]
    return gait_atlas(paper, schedules, psi0s, zeta0s, row_label="psi0", column_label="zeta0")


def test_symmetric_atlas_finds_the_period_one_gait_and_no_unstable_one(paper, symmetric):
    atlas = _symmetric(paper, [30.0], [0.9, 0.97])
    (gaits_09, gaits_097) = atlas.gaits
    reference = find_fixed_point(paper, symmetric, 1, (-0.9, -0.2))
    assert len(gaits_09) == 1 and gaits_09[0].period == 1
    np.testing.assert_allclose(gaits_09[0].state, reference.state, atol=1e-9)
    assert gaits_097 == (), "at zeta0 = 0.97 the period-1 gait is unstable (|λ| ≈ 1.01)"
    assert atlas.period.tolist() == [[1, 0]]
    assert atlas.climb_per_jump[0, 0] == pytest.approx(reference.climb_per_period)
    assert np.isnan(atlas.climb_per_jump[0, 1])


def test_alternating_atlas_finds_period_two_and_four(paper):
    zeta0_left, zeta0_right = [0.9], [0.9, 0.95]
    schedules = [
        ControlSchedule.from_degrees([(30.0, left), (35.0, right)]) for left in zeta0_left for right in zeta0_right
    ]
    atlas = gait_atlas(paper, schedules, zeta0_left, zeta0_right, row_label="zeta0_L", column_label="zeta0_R")
    assert atlas.period.tolist() == [[2, 4]], "period doubling between zeta0_R 0.90 and 0.95 (Fig. 7)"
    assert all(gait.stable for cell in atlas.gaits for gait in cell)
    payload = atlas.to_dict()
    assert payload["period"] == [[2, 4]] and len(payload["cells"]) == 2


def test_bad_atlas_specs_are_rejected(paper, symmetric):
    with pytest.raises(ParameterError, match=r"^schedules:"):
        gait_atlas(paper, [symmetric], [1.0, 2.0], [1.0], row_label="a", column_label="b")
    with pytest.raises(ParameterError, match=r"^grid:"):
        gait_atlas(paper, [], [], [1.0], row_label="a", column_label="b")
