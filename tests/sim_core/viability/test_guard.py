"""sim_core/viability/guard.py: the compiled guard answers as the engine's own transition map does
for the grid's pairs, and refuses what lies past the grid."""

import math

import numpy as np
import pytest

from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.stride import lift_off
from sim_core.viability.engine import ViabilityGrid, compute_viability
from sim_core.viability.grid import DEFAULT_XDOT, DEFAULT_YDOT
from sim_core.viability.guard import design_guard, lands_in_kernel
from sim_core.viability.step_map import section_step_map

NO_RECORD = np.empty((0, STATE_SIZE))
PSI0_DEG = 32.0
ZETA0_RANGE = (0.8, 0.98)


@pytest.fixture(scope="module")
def guard(paper):
    return np.array(design_guard(paper, PSI0_DEG, ZETA0_RANGE, states=24, actions=7))


def test_the_guard_allows_exactly_the_viable_pairs_of_the_grid(paper, guard):
    grid = ViabilityGrid(
        (np.linspace(*DEFAULT_XDOT, 24), np.linspace(*DEFAULT_YDOT, 24)),
        (np.array([math.radians(PSI0_DEG)]), np.linspace(*ZETA0_RANGE, 7)),
    )
    result = compute_viability(section_step_map(paper), grid)
    d_hat = paper.d_hat
    psi0 = math.radians(PSI0_DEG)
    checked = 0
    for (i, j, _, k), viable in np.ndenumerate(result.viable_pairs):
        if result.failed[i, j, 0, k] or not result.kernel[i, j]:
            continue
        # The pair's stance, from the node's flight to the wall.
        xdot, ydot, zeta0 = grid.state_axes[0][i], grid.state_axes[1][j], grid.action_axes[1][k]
        time = (0.5 * d_hat - zeta0 * math.cos(psi0)) / xdot
        status, psi, vx, vy, _, _ = lift_off(-xdot, ydot - time, psi0, zeta0, paper.record(), NO_RECORD)
        assert status == OK
        assert lands_in_kernel(guard, 0, psi, vx, vy, d_hat) == viable, (i, j, k)
        checked += 1
    assert checked > 100 and 0 < result.viable_pairs.mean() < 1


def test_a_landing_past_the_grid_or_a_flight_back_is_refused(paper, guard):
    d_hat = paper.d_hat
    assert not lands_in_kernel(guard, 0, math.radians(40.0), 50.0, 0.0, d_hat)  # far past xdot's range
    assert not lands_in_kernel(guard, 0, math.radians(40.0), -1.0, 0.0, d_hat)  # flying away from the wall
