"""Gaits and stability against the paper's qualitative results (docs/model.md §5)."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import (
    PAPER_GAITS,
    ControlSchedule,
    FixedPointNotFound,
    NoGaitFound,
    ParameterError,
    find_fixed_point,
    gait_of,
    iterate_map,
    map_jacobian,
    search_gaits,
)
from tests.sim_core import cartesian_reference
from tests.sim_core.test_poincare import _params

RESIDUAL_TOL = 1e-9
SAME_STATE_TOL = 1e-9  # two solves of one gait agree to the residual tolerance
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
PERIOD4 = ControlSchedule.from_degrees(PAPER_GAITS["period 4"])
PERIOD2_OF_PERIOD4 = (-0.752, -0.398)  # near the unstable period-2 orbit of the period-4 controls
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


def test_search_finds_distinct_gaits(paper):
    gaits = search_gaits(paper, ControlSchedule.from_degrees([(30.0, 0.98)]), 1)
    assert len(gaits) >= 1
    states = np.array([gait.state for gait in gaits])
    assert len({tuple(np.round(state, 6)) for state in states}) == len(gaits)
    assert [gait.stable for gait in gaits] == sorted((gait.stable for gait in gaits), reverse=True)


def test_guess_in_failing_region_is_reported(paper, symmetric):
    with pytest.raises(FixedPointNotFound, match="fails from the guess"):
        find_fixed_point(paper, symmetric, 1, (-5.0, 0.0))


def test_period_must_be_multiple_of_schedule(paper, alternating):
    with pytest.raises(ParameterError, match="multiple of the control schedule's length 2"):
        find_fixed_point(paper, alternating, 3, (-0.8, -0.15))


def test_gait_of_without_a_guess_is_the_most_stable_of_a_search(paper, alternating):
    gait = gait_of(paper, alternating)
    best = search_gaits(paper, alternating, 2)[0]
    assert gait.period == 2 and gait.stable, "the period defaults to the schedule's length"
    assert_allclose(gait.state, best.state, rtol=0, atol=SAME_STATE_TOL)


def test_gait_of_from_a_guess_is_levenberg_marquardt(paper):
    unstable = gait_of(paper, PERIOD4, 4, PERIOD2_OF_PERIOD4)
    direct = find_fixed_point(paper, PERIOD4, 4, PERIOD2_OF_PERIOD4)
    assert unstable.period == 2 and not unstable.stable, "the guess's gait, though a stable one exists"
    assert_allclose(unstable.state, direct.state, rtol=0, atol=SAME_STATE_TOL)
    with pytest.raises(FixedPointNotFound, match="fails from the guess") as failed:
        gait_of(paper, PERIOD4, 4, (-5.0, 0.0))
    assert not isinstance(failed.value, NoGaitFound), "a failing guess is reported, not searched around"


def test_gait_of_prefer_stable_searches_past_an_unstable_or_failing_guess(paper):
    for guess in (PERIOD2_OF_PERIOD4, (-5.0, 0.0)):
        gait = gait_of(paper, PERIOD4, 4, guess, grid=(4, 4), prefer_stable=True)
        assert gait.period == 4 and gait.stable, guess


def test_gait_of_prefer_stable_keeps_a_stable_guess(paper, symmetric):
    near = gait_of(paper, symmetric, guess=(-0.93, -0.2), grid=(1, 1), prefer_stable=True)
    assert near.stable
    assert_allclose(near.state, find_fixed_point(paper, symmetric, 1, (-0.93, -0.2)).state, atol=SAME_STATE_TOL)


def test_gait_of_prefer_stable_falls_back_to_the_least_unstable(paper):
    only_unstable = ControlSchedule.from_degrees([(30.0, 0.98)])
    gait = gait_of(paper, only_unstable, guess=(-3.77, -3.63), prefer_stable=True)
    assert not gait.stable
    assert gait.max_abs_eigenvalue == pytest.approx(search_gaits(paper, only_unstable, 1)[0].max_abs_eigenvalue)
    assert gait.max_abs_eigenvalue < 1.5, "the grid's best, not the guess's far worse gait"


def test_gait_of_without_any_gait_says_what_to_do(paper):
    steep = ControlSchedule.from_degrees([(80.0, 0.99)])
    with pytest.raises(NoGaitFound) as none:
        gait_of(paper, steep, grid=(3, 3))
    assert str(none.value) == "no period-1 gait found for controls 80°:0.99; give a starting state explicitly"
    assert none.value.period == 1 and none.value.schedule == steep
    assert isinstance(none.value, FixedPointNotFound), "callers catching FixedPointNotFound still do"


def test_gait_of_checks_its_arguments(paper, alternating):
    with pytest.raises(ParameterError, match=r"^period: "):
        gait_of(paper, alternating, 3)
    with pytest.raises(ParameterError, match=r"^grid: "):
        gait_of(paper, alternating, grid=(0, 4))


def test_to_dict_is_the_whole_gait_as_json(paper, alternating):
    gait = find_fixed_point(paper, alternating, 2, (-0.8, -0.15))
    payload = gait.to_dict()
    assert list(payload) == GAIT_KEYS
    assert payload["motion"] == gait.motion == "climbing"
    assert payload["orbit"] == gait.orbit.tolist() and len(payload["orbit"]) == gait.period == 2
    assert json.loads(json.dumps(payload, allow_nan=False)) == payload, "plain JSON types only"
