"""sim_core/viability/kernels.py: the corner rule and one shrinking sweep on a map small enough to
follow by hand (the engine as a whole is checked against vibly's algorithm in test_viability.py)."""

import numpy as np

from sim_core.viability.kernels import pair_measures, shrink


def test_a_chain_of_states_unravels_from_its_doomed_end():
    # Five states on a line, one action: state i lands between nodes i and i + 1 (bin i + 1),
    # state 4's landing is past the grid's last node. Its loss spreads down the chain one
    # state per sweep, and a final sweep sees nothing change.
    bins = np.array([[1], [2], [3], [4], [5]])
    viable = np.array([True, True, True, True, False])
    kernel = np.empty(5, dtype=bool)
    sweeps = shrink(bins, viable, kernel, np.array([5]), 1)
    assert not kernel.any() and not viable.any()
    assert sweeps == 5


def test_a_pair_landing_between_kernel_nodes_stays_and_carries_their_mean_measure():
    # Two states, two actions each: state 0's first action lands between nodes 0 and 1, state 1's
    # second action lands on the same bin; the other two actions fail.
    bins = np.array([[1], [-1], [-1], [1]])
    viable = np.array([True, False, False, True])
    kernel = np.empty(2, dtype=bool)
    assert shrink(bins, viable, kernel, np.array([2]), 2) == 1
    assert kernel.all()
    out = np.empty(4)
    pair_measures(bins, viable, np.array([0.5, 0.5]), np.array([2]), out)
    np.testing.assert_allclose(out, [0.5, 0.0, 0.0, 0.5])
