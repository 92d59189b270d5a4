"""sim_core/viability/engine.py: the kernel of a map whose kernel is known in closed form, cell for cell
agreement with a plain transcription of vibly's algorithm, and the grid's errors."""

import itertools

import numpy as np
import pytest

from sim_core.model.validation import ParameterError
from sim_core.viability.engine import FAILED, ViabilityGrid, compute_viability, viability_of_map


def linear_step(gain, bound):
    """``x' = gain x + a``, failing past ``|x'| > bound``."""

    def step(states, actions):
        reached = gain * states + actions
        return reached, np.abs(reached[:, 0]) > bound

    return step


@pytest.mark.parametrize("seed", [3, 17, 29])
def test_the_kernel_of_an_expanding_map_is_its_known_interval_within_the_grid_error(seed):
    # x' = g x + a with |a| <= A stays bounded forever exactly on |x| <= A / (g - 1). The grid's
    # kernel is conservative: inside that interval, and holding every node at least
    # h / (g - 1) inside it (from there the worst landing's bin corners stay inside too).
    rng = np.random.default_rng(seed)
    gain, reach = rng.uniform(1.5, 3.0), rng.uniform(0.3, 1.0)
    edge = reach / (gain - 1.0)
    states = np.linspace(-3.0, 3.0, 301)
    grid = ViabilityGrid((states,), (np.linspace(-reach, reach, 41),))
    result = compute_viability(linear_step(gain, 4.0), grid)
    spacing = states[1] - states[0]
    assert np.all(np.abs(states[result.kernel]) <= edge + 1e-9)
    assert np.all(result.kernel[np.abs(states) <= edge - spacing / (gain - 1.0) - 1e-9])
    assert result.sweeps > 1


def test_an_axis_the_map_carries_unchanged_keeps_the_kernel_of_the_others():
    """A state the map carries over as it is (the ParkourBot's pitch, in the noiseless map) lands
    on its own node: on the last node too, which the closed grid keeps in its last bin (plain
    np.digitize would put it past the grid, and the kernel would empty from there down)."""
    gain, reach = 2.0, 0.5
    states = np.linspace(-1.5, 1.5, 61)
    expanding = linear_step(gain, 4.0)

    def step(states, actions):  # x' = g x + a, c' = c
        reached, failed = expanding(states[:, :1], actions)
        return np.column_stack([reached[:, 0], states[:, 1]]), failed

    grid = ViabilityGrid((states, np.linspace(0.0, 1.0, 3)), (np.linspace(-reach, reach, 21),))
    carried = compute_viability(step, grid)
    alone = compute_viability(expanding, ViabilityGrid((states,), (np.linspace(-reach, reach, 21),)))
    for node in range(3):
        np.testing.assert_array_equal(carried.kernel[:, node], alone.kernel)
    assert alone.kernel.any()


def vibly_viable_pairs(failed, bins, state_shape, edges_extend):
    """vibly's compute_QV written out plainly: keep a pair while it does not fail and every
    existing node around the bin it reaches is in the kernel; repeat until nothing changes."""
    dims = len(state_shape)
    viable = ~failed.copy()
    for index in np.ndindex(failed.shape):
        bin_index = bins[index]
        if edges_extend:
            viable[index] &= bool(np.any(bin_index != 0))
        else:
            viable[index] &= all(1 <= b <= n - 1 for b, n in zip(bin_index, state_shape, strict=True))
    while True:
        kernel = viable.reshape(*state_shape, -1).any(axis=-1)
        changed = False
        for index in np.ndindex(failed.shape):
            if not viable[index]:
                continue
            corners = [
                node
                for node in itertools.product(*[(b - 1, b) for b in bins[index]])
                if all(0 <= i < n for i, n in zip(node, state_shape, strict=True))
            ]
            if not all(kernel[node] for node in corners):
                viable[index] = False
                changed = True
        if not changed:
            return viable, kernel
    assert dims


@pytest.mark.parametrize("edges_extend", [True, False])
@pytest.mark.parametrize("seed", [0, 1, 3])
def test_the_fixed_point_is_vibly_s_on_random_transition_maps(seed, edges_extend):
    rng = np.random.default_rng(seed)
    grid = ViabilityGrid((np.arange(7.0), np.arange(6.0)), (np.arange(3.0), np.arange(2.0)))
    failed = rng.random(grid.shape) < 0.3
    failed[:2] = True  # doomed states: whatever lands near them is not viable either
    # Each pair lands a node or two from where it starts: the doomed states' loss spreads, not everywhere.
    x_index, y_index = np.indices(grid.shape)[:2]
    x_bins = np.clip(x_index + rng.integers(-1, 3, grid.shape), 0, 7)
    y_bins = np.clip(y_index + rng.integers(0, 2, grid.shape), 0, 6)
    bins = np.stack([x_bins, y_bins], axis=-1)
    bins[failed] = FAILED
    result = viability_of_map(grid, failed, bins, edges_extend=edges_extend)
    viable, kernel = vibly_viable_pairs(failed, bins, grid.state_shape, edges_extend)
    assert np.array_equal(result.viable_pairs, viable)
    assert np.array_equal(result.kernel, kernel)
    assert 0 < kernel.sum() < kernel.size, "the random map should keep some states and lose others"
    measure = viable.reshape(*grid.state_shape, -1).mean(axis=-1)
    assert np.allclose(result.measure, measure)
    # vibly's Q_M: the mean measure of the existing nodes around where a viable pair lands.
    index = tuple(np.argwhere(viable)[0])
    corners = [
        node
        for node in itertools.product(*[(b - 1, b) for b in bins[index]])
        if all(0 <= i < n for i, n in zip(node, grid.state_shape, strict=True))
    ]
    assert result.pair_measure[index] == pytest.approx(np.mean([measure[node] for node in corners]))
    assert np.all(result.pair_measure[~viable] == 0.0)


def test_chunks_and_progress_do_not_change_the_result():
    grid = ViabilityGrid((np.linspace(-3, 3, 61),), (np.linspace(-1, 1, 9),))
    step = linear_step(2.0, 4.0)
    calls = []
    chunked = compute_viability(step, grid, chunk_pairs=100, progress=lambda done, total: calls.append((done, total)))
    whole = compute_viability(step, grid)
    assert np.array_equal(chunked.viable_pairs, whole.viable_pairs) and np.array_equal(chunked.bins, whole.bins)
    assert calls[-1] == (len(calls), len(calls)) and len(calls) == -(-grid.pairs // 100)


def test_a_step_that_returns_non_finite_states_counts_as_failing():
    def step(states, actions):
        return np.where(actions > 0, np.nan, 0.0 * states), np.zeros(states.shape[0], dtype=bool)

    grid = ViabilityGrid((np.linspace(-1, 1, 5),), (np.array([-1.0, 1.0]),))
    result = compute_viability(step, grid)
    assert np.all(result.failed[:, 1]) and not np.any(result.failed[:, 0])
    assert np.all(result.bins[:, 1] == FAILED)
    assert np.all(result.kernel) and np.allclose(result.measure, 0.5)


def test_the_result_reads_as_numbers_and_answers_for_one_state():
    grid = ViabilityGrid((np.linspace(-3, 3, 31),), (np.linspace(-0.5, 0.5, 5),))
    result = compute_viability(linear_step(2.0, 4.0), grid)
    payload = result.to_dict()
    assert payload["cells"] == 31 and payload["pairs"] == 155
    assert payload["kernel_cells"] == int(result.kernel.sum()) and len(payload["kernel"]) == 31
    assert 0 < payload["kernel_fraction"] < 1 and 0 < payload["measure_mean"] <= 1
    centre = result.nearest_node([0.01])
    assert centre == (15,) and result.kernel[centre]
    assert np.array_equal(result.viable_actions(centre)[:, 0], grid.action_axes[0][result.viable_pairs[15]])
    with pytest.raises(ParameterError, match="state: must have 1 components"):
        result.nearest_node([0.0, 1.0])


def test_a_step_that_reaches_the_maps_goal_is_viable_whatever_follows():
    """A climber that rises one node a step leaves any grid: nothing is viable, unless reaching the
    top is the goal (a world's chute climbed); then every state is, with all the room there is."""
    grid = ViabilityGrid((np.arange(6.0), np.array([-1.0, 1.0])), (np.array([0.0, 1.0]),))

    def rising(states, actions, goal=None):
        reached = states + np.array([1.0, 0.0])
        failed = np.zeros(len(states), dtype=bool)
        return (reached, failed) if goal is None else (reached, failed, reached[:, 0] >= goal)

    assert not compute_viability(rising, grid).kernel.any()
    climbed = compute_viability(lambda s, a: rising(s, a, goal=5.0), grid)
    assert climbed.kernel.all() and (climbed.pair_measure[climbed.bins[..., 0] == -2] == 1.0).all()
