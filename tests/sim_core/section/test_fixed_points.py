"""Fixed points and their stability against the paper's qualitative results (docs/model.md §5);
the gait search and gait_of: test_gait_search.py."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import (
    ControlSchedule,
    FixedPointNotFound,
    ParameterError,
    characterize,
    find_fixed_point,
    iterate_map,
    map_jacobian,
    minimal_period,
)
from tests.sim_core import cartesian_reference
from tests.sim_core.model.test_poincare import _params

RESIDUAL_TOL = 1e-9
GAIT_KEYS = [  # FixedPoint.to_dict, in order: also `parkour fixed-point --json` and each of `gaits --json`
    "state",
    "period",
    "eigenvalues",
    "max_abs_eigenvalue",
    "stable",
    "climb_per_period",
    "residual",
    "motion",
    "orbit",
]
JACOBIAN_ATOL = 1e-6  # central differences of the Cartesian reference are good to ~1e-7


def test_paper_period1_gait_is_stable_and_climbs(paper, symmetric):
    gait = find_fixed_point(paper, symmetric, 1, (-1.0, 0.0))
    assert gait.period == 1 and gait.stable and gait.motion == "climbing"
    assert gait.residual <= RESIDUAL_TOL
    image = iterate_map(paper, symmetric, gait.state, 1).states[-1]
    assert_allclose(image, gait.state, rtol=0, atol=RESIDUAL_TOL, err_msg="fixed point maps to itself")


def test_paper_period2_gait_is_stable(paper, alternating):
    gait = find_fixed_point(paper, alternating, 2, (-0.8, -0.15))
    assert gait.period == 2 and gait.stable and gait.climb_per_period > 0
    assert not np.allclose(gait.orbit[0], gait.orbit[1]), "a true period-2 orbit has two distinct states"
    image = iterate_map(paper, alternating, gait.state, 2).states[-1]
    assert_allclose(image, gait.state, rtol=0, atol=RESIDUAL_TOL)


def test_minimal_period_is_reported(paper, symmetric):
    gait = find_fixed_point(paper, symmetric, 2, (-1.0, 0.0))
    assert gait.period == 1


def test_jacobian_agrees_with_reference_differences(paper, alternating):
    gait = find_fixed_point(paper, alternating, 2, (-0.8, -0.15))
    schedule_deg = [(30.0, 0.87), (30.0, 0.9)]
    step = 1e-4
    reference = np.empty((2, 2))
    for column in range(2):
        shift = np.zeros(2)
        shift[column] = step
        plus = cartesian_reference.run(_params(paper), schedule_deg, gait.state + shift, 2).section_states[-1]
        minus = cartesian_reference.run(_params(paper), schedule_deg, gait.state - shift, 2).section_states[-1]
        reference[:, column] = (plus - minus) / (2 * step)
    assert_allclose(gait.jacobian, reference, rtol=0, atol=JACOBIAN_ATOL)
    assert_allclose(map_jacobian(paper, alternating, gait.state, 2), gait.jacobian, rtol=0, atol=1e-12)


def test_more_retraction_is_more_stable_and_climbs_faster(paper):
    """Fig. 8: sweeping zeta0 (symmetric, psi0 = 30°), max |λ| and climb both improve with
    retraction, and the climb changes sign: a zeta0 of jumping in place lies in between."""
    guess = (-0.93, 0.0)
    max_eigen, climb = [], []
    for zeta0 in np.linspace(0.80, 0.98, 10):
        gait = find_fixed_point(paper, ControlSchedule.from_degrees([(30.0, zeta0)]), 1, guess)
        guess = tuple(gait.state)  # continuation
        max_eigen.append(gait.max_abs_eigenvalue)
        climb.append(gait.climb_per_period)
    assert np.all(np.diff(max_eigen) > 0), "max |λ| grows as retraction decreases"
    assert np.all(np.diff(climb) < 0), "climb shrinks as retraction decreases"
    assert climb[0] > 0 > climb[-1], "climbing at zeta0 = 0.80, descending at 0.98"


def test_guess_in_failing_region_is_reported(paper, symmetric):
    with pytest.raises(FixedPointNotFound, match="fails from the guess"):
        find_fixed_point(paper, symmetric, 1, (-5.0, 0.0))


def test_period_must_be_multiple_of_schedule(paper, alternating):
    with pytest.raises(ParameterError, match="multiple of the control schedule's length 2"):
        find_fixed_point(paper, alternating, 3, (-0.8, -0.15))


def test_to_dict_is_the_whole_gait_as_json(paper, alternating):
    gait = find_fixed_point(paper, alternating, 2, (-0.8, -0.15))
    payload = gait.to_dict()
    assert list(payload) == GAIT_KEYS
    assert payload["motion"] == gait.motion == "climbing"
    assert payload["orbit"] == gait.orbit.tolist() and len(payload["orbit"]) == gait.period == 2
    assert json.loads(json.dumps(payload, allow_nan=False)) == payload, "plain JSON types only"


def test_characterize_describes_a_fixed_point_by_its_minimal_period(paper, symmetric):
    gait = find_fixed_point(paper, symmetric, 1, (-1.0, 0.0))
    again = characterize(paper, symmetric, gait.state, 3)
    assert again.period == 1 == minimal_period(paper, symmetric, gait.state, 3)
    assert again.residual <= 3 * RESIDUAL_TOL, "the residual of P^3, computed when not given"
    assert_allclose(again.eigenvalues, gait.eigenvalues, rtol=0, atol=1e-12)
    assert again.rises.shape == (1,) and again.climb_per_period == gait.climb_per_period


def test_a_state_off_the_gait_keeps_the_requested_period(paper, symmetric):
    assert minimal_period(paper, symmetric, (-1.0, 0.0), 4) == 4, "no shorter period returns to the state"
