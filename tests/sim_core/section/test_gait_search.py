"""Which gait: the grid search and gait_of, from a guess or the most stable of a search (docs/model.md §4)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sim_core import PAPER_GAITS, ControlSchedule, FixedPointNotFound, NoGaitFound, ParameterError, find_fixed_point
from sim_core.section.gait_search import gait_of, search_gaits

SAME_STATE_TOL = 1e-9  # two solves of one gait agree to the residual tolerance
PERIOD4 = ControlSchedule.from_degrees(PAPER_GAITS["period 4"])
PERIOD2_OF_PERIOD4 = (-0.752, -0.398)  # near the unstable period-2 orbit of the period-4 controls


def test_search_finds_distinct_gaits(paper):
    gaits = search_gaits(paper, ControlSchedule.from_degrees([(30.0, 0.98)]), 1)
    assert len(gaits) >= 1
    states = np.array([gait.state for gait in gaits])
    assert len({tuple(np.round(state, 6)) for state in states}) == len(gaits)
    assert [gait.stable for gait in gaits] == sorted((gait.stable for gait in gaits), reverse=True)


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


def test_search_keeps_one_gait_per_orbit_and_phase(paper, alternating):
    """Every guess of a 3 x 3 grid that converges lands on one of few orbits: each is listed once."""
    gaits = search_gaits(paper, alternating, 2, grid=(3, 3))
    assert gaits, "the paper's period-2 gait is found"
    for i, a in enumerate(gaits):
        for b in gaits[i + 1 :]:
            assert np.min(np.linalg.norm(b.orbit[::2] - a.state, axis=1)) > 1e-6, "a repeated orbit"


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"xdot_range": (-1.0, 0.5)}, "xdot_range"),
        ({"xdot_range": (-0.5, -1.0)}, "xdot_range"),
        ({"ydot_range": (1.0, -1.0)}, "ydot_range"),
        ({"grid": (0, 3)}, "grid"),
        ({"grid": (3, 101)}, "grid"),
    ],
)
def test_search_checks_its_ranges(paper, symmetric, options, field):
    with pytest.raises(ParameterError, match=f"^{field}: "):
        search_gaits(paper, symmetric, 1, **options)
