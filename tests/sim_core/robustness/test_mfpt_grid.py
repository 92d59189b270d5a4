"""sim_core/robustness/mfpt_grid.py: the noise rule's moments, the pitch stencil, the axes and the states kept."""

import math

import numpy as np
import pytest
from scipy.stats import norm

from sim_core.model.errors import ParameterError
from sim_core.robustness.mfpt_grid import (
    MAX_STATES,
    ChainGrid,
    check_states,
    kept_states,
    pitch_axis,
    pitch_stencil,
    quadrature,
    velocity_axis,
)


@pytest.mark.parametrize("points", [2, 3, 5, (4, 3, 2, 2)])
def test_the_rule_has_the_gaussians_mean_and_variance(points):
    sigmas = (0.0087, 0.003, 0.01, 0.02)
    draws, weights = quadrature(sigmas, points)
    assert weights.sum() == pytest.approx(1.0, abs=1e-12)
    assert np.all(weights > 0)
    np.testing.assert_allclose(weights @ draws, 0.0, atol=1e-15)
    np.testing.assert_allclose(weights @ draws**2, np.square(sigmas), rtol=1e-12)
    # Independent components: no covariance between them.
    covariance = (draws * weights[:, None]).T @ draws
    np.testing.assert_allclose(covariance - np.diag(np.diag(covariance)), 0.0, atol=1e-15)


@pytest.mark.parametrize("threshold", [1.0, 1.5, 2.0, 2.5])
def test_a_threshold_in_the_noise_is_met_with_its_probability_within_a_quarter_sigma(threshold):
    # Whether a jump fails is a threshold in the noise: the rule's mass beyond it lies between the
    # Gaussian's beyond threshold -/+ 0.25 sigma. (A 3-point Hermite rule puts 1/6 beyond 1.5
    # sigma, more than the Gaussian's 0.106 beyond 1.25.)
    draws, weights = quadrature((1.0,), 16)
    beyond = weights[draws[:, 0] > threshold].sum()
    assert norm.sf(threshold + 0.25) <= beyond <= norm.sf(threshold - 0.25)


def test_the_outer_strata_reach_into_the_tails():
    draws, weights = quadrature((1.0,), 8)
    assert draws.max() > 2.5 and weights[draws[:, 0] > 2.5].sum() == pytest.approx(norm.sf(2 * norm.ppf(7 / 8)))


def test_a_zero_sigma_is_one_point_at_zero():
    draws, weights = quadrature((0.0, 0.5), 3)
    assert draws.shape == (3, 2) and np.all(draws[:, 0] == 0.0)
    assert weights.sum() == pytest.approx(1.0)


@pytest.mark.parametrize("spacing_sigmas", [0.35, 0.5, 1.0])
def test_the_pitch_stencil_is_a_symmetric_discrete_gaussian(spacing_sigmas):
    sigma = math.radians(0.5)
    offsets, weights = pitch_stencil(sigma, spacing_sigmas * sigma)
    assert weights.sum() == pytest.approx(1.0)
    np.testing.assert_array_equal(offsets, -offsets[::-1])
    np.testing.assert_allclose(weights, weights[::-1])
    variance = weights @ (offsets * spacing_sigmas * sigma) ** 2
    assert variance == pytest.approx(sigma**2, rel=0.01)


def test_no_drift_is_one_pitch_node_and_a_step_of_zero():
    offsets, weights = pitch_stencil(0.0, 1.0)
    assert offsets.tolist() == [0] and weights.tolist() == [1.0]
    assert pitch_axis(np.array([0.1]), 0.0, 1.0).tolist() == [0.0]


def test_the_pitch_axis_is_symmetric_with_zero_a_node_and_reaches_past_the_paths():
    sigma = math.radians(0.5)
    axis = pitch_axis(np.array([-0.1, 0.2]), sigma, 0.5 * sigma)
    assert axis.size % 2 == 1 and axis[axis.size // 2] == 0.0
    np.testing.assert_allclose(axis, -axis[::-1])
    assert axis[-1] >= 0.2 + 3.9 * sigma


def test_the_velocity_axis_is_uniform_over_the_core_and_reaches_the_window():
    rng = np.random.default_rng(3)
    values = rng.normal(1.0, 0.05, 20_000)
    axis = velocity_axis(values, 30, 1.0, 1.5, floor=1e-3)
    spacing = np.diff(axis)
    assert np.all(spacing > 0)
    assert axis[0] == pytest.approx(1e-3) and axis[-1] == pytest.approx(2.5)
    core = spacing.min()
    assert np.sum(np.isclose(spacing, core, rtol=1e-9)) == 29, "30 uniform core nodes"
    assert core < 0.2 * 0.05 * 2, "the core's spacing is a fraction of the paths' spread"


def test_kept_states_cover_the_visited_cells_and_their_margin():
    xdots = np.linspace(0.0, 1.0, 11)
    ydots = np.linspace(0.0, 1.0, 11)
    pitches = np.arange(-3, 4) * 0.1
    visited = np.array([[0.55, 0.55, 0.0]])
    kept = kept_states(visited, xdots, ydots, pitches, margin=0)
    assert kept.sum() == 4 and kept[3, 5:7, 5:7].all()
    grown = kept_states(visited, xdots, ydots, pitches, margin=1)
    assert grown[2:5, 4:8, 4:8].all() and grown.sum() == 3 * 4 * 4
    assert kept_states(visited, xdots, ydots, np.zeros(1), margin=0).all(), "one layer keeps every node"


@pytest.mark.parametrize(
    ("field", "value"),
    [("velocity_nodes", 3), ("velocity_nodes", 401), ("pitch_spacing", 0.0), ("strata", (4, 3, 2)), ("paths", 5)],
)
def test_a_bad_grid_is_refused_naming_its_field(field, value):
    with pytest.raises(ParameterError) as error:
        ChainGrid(**{field: value})
    assert error.value.field == f"grid.{field}"


def test_exploring_paths_whose_draws_would_not_fit_in_memory_are_refused():
    ChainGrid(paths=10_000, path_jumps=1000)
    with pytest.raises(ParameterError, match="paths x path_jumps must be at most 10,000,000"):
        ChainGrid(paths=10_000, path_jumps=1001)


def test_too_many_states_are_refused_before_memory_is_taken():
    check_states(MAX_STATES)
    with pytest.raises(ParameterError, match="memory"):
        check_states(MAX_STATES + 1)


def test_refining_multiplies_the_nodes_and_divides_the_pitch_spacing():
    grid = ChainGrid(velocity_nodes=20, pitch_spacing=0.7)
    finer = grid.refined(2.0)
    assert finer.velocity_nodes == 40 and finer.pitch_spacing == pytest.approx(0.35)
    assert finer.strata == grid.strata
    coarsest = ChainGrid(velocity_nodes=5, pitch_spacing=3.5).refined(0.5)
    assert (coarsest.velocity_nodes, coarsest.pitch_spacing) == (4, 4.0), "kept within the ranges"
