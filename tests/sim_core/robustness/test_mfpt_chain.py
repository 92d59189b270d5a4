"""sim_core/robustness/mfpt_chain.py: the chain's solve and its largest eigenvalue against dense linear algebra."""

import numpy as np
import pytest
from scipy import sparse

from sim_core.robustness.mfpt_chain import Chain, expected_jumps, largest_eigenvalue


def chain_of(matrix, success, layers: int = 1) -> Chain:
    # The matrix as the chain keeps it: steps (here the identity) then jumps. One pitch layer is
    # solved directly, several iteratively.
    matrix = sparse.csr_matrix(matrix)
    empty = np.zeros(1)
    steps = sparse.identity(matrix.shape[0], format="csr")
    state_of = np.zeros((layers, 1), dtype=np.int64)
    return Chain(empty, empty, np.zeros(layers), state_of, steps, matrix, np.asarray(success, float), 0.0)


def test_one_state_that_stays_with_probability_p_lasts_one_over_one_minus_p():
    chain = chain_of([[0.999]], [1.0])
    assert expected_jumps(chain)[0] == pytest.approx(1000.0, rel=1e-9)
    assert largest_eigenvalue(chain) == pytest.approx(0.999)


@pytest.mark.parametrize("layers", [1, 5])
@pytest.mark.parametrize("seed", [1, 2])
def test_the_solve_and_the_eigenvalue_are_dense_linear_algebra_s(monkeypatch, seed, layers):
    # The size alone never picks the factorisation.
    monkeypatch.setattr("sim_core.robustness.mfpt_chain.DIRECT_SOLVE_STATES", 0)
    rng = np.random.default_rng(seed)
    states = 300
    matrix = sparse.random(states, states, density=0.03, random_state=rng, format="csr")
    rows = np.asarray(matrix.sum(axis=1)).ravel()
    keep = rng.uniform(0.95, 0.999, states)  # each row loses 0.1-5% to failure
    matrix = sparse.diags(keep / np.where(rows > 0, rows, 1.0)) @ matrix
    success = np.asarray(matrix.sum(axis=1)).ravel() + rng.uniform(0, 1, states) * (1 - keep)
    chain = chain_of(matrix, success, layers)
    dense = matrix.toarray()
    np.testing.assert_allclose(expected_jumps(chain), np.linalg.solve(np.eye(states) - dense, success), rtol=1e-8)
    assert largest_eigenvalue(chain) == pytest.approx(np.max(np.abs(np.linalg.eigvals(dense))), rel=1e-8)
