"""The benchmark's scipy baseline agrees with the kernel (else the bench's ratio means nothing)."""

import numpy as np
from numpy.testing import assert_allclose

from sim_core import iterate_map_batch
from sim_core.model.failures import OK
from sim_core.model.reference import reference_jumps


def test_baseline_agrees_with_kernel(paper, symmetric):
    rng = np.random.default_rng(3)
    states = np.column_stack([rng.uniform(-1.1, -0.8, 8), rng.uniform(-0.4, 0.1, 8)])
    status, next_states, rises = reference_jumps(paper, states, symmetric[0], symmetric[1], rtol=1e-11, atol=1e-11)
    batch = iterate_map_batch(paper, symmetric, states, 1)
    assert np.all(status == OK) and np.all(batch.status == OK)
    assert_allclose(batch.states[:, 1], next_states, rtol=0, atol=1e-8)
    assert_allclose(batch.rises[:, 0], rises, rtol=0, atol=1e-8)
