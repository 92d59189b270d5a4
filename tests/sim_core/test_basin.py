"""Basins of attraction: against the scipy path, the gait's own cell, phases, Fig. 8's trend."""

import numpy as np
import pytest

from sim_core import ControlSchedule, ParameterError, find_fixed_point
from sim_core.basin import NOT_CONVERGED, compute_basin
from sim_core.basin_grid import BasinGrid
from sim_core.failures import OK
from sim_core.reference import reference_jump


@pytest.fixture(scope="module")
def gait(paper, symmetric):
    return find_fixed_point(paper, symmetric, 1, (-0.9, -0.2))


def _reference_convergence(model, schedule, gait, start, max_jumps, tolerance):
    """The basin test for one start, iterating the scipy baseline jump by jump."""
    state = np.asarray(start, dtype=float)
    m = len(schedule)
    for k in range(max_jumps + 1):
        phase = k % m
        if min(np.hypot(*(state - gait.orbit[j])) for j in range(phase, gait.period, m)) < tolerance:
            return k, OK
        if k == max_jumps:
            break
        status, xdot, ydot, _ = reference_jump(model, state, schedule[k % m], schedule[(k + 1) % m])
        if status != OK:
            return NOT_CONVERGED, status
        state = np.array([xdot, ydot])
    return NOT_CONVERGED, OK


def test_basin_agrees_with_scipy_path(paper, symmetric, gait):
    grid = BasinGrid((-2.4, -0.1), (-1.6, 1.4), 5)
    basin = compute_basin(paper, symmetric, gait, grid, max_jumps=25, tolerance=0.02)
    expected = [_reference_convergence(paper, symmetric, gait, start, 25, 0.02) for start in grid.states()]
    assert basin.jumps_to_converge.ravel().tolist() == [jumps for jumps, _ in expected]
    assert basin.failure.ravel().tolist() == [status for _, status in expected]
    counts = basin.outcome_counts()
    assert counts["converged"] > 0 and sum(counts.values()) == 25, "a mix of outcomes makes this test meaningful"
    assert counts["converged"] < 25


def test_gait_lies_in_its_own_basin(paper, symmetric, gait):
    basin = compute_basin(paper, symmetric, gait, BasinGrid.around(gait.state, 3, half_width=0.05))
    assert basin.jumps_to_converge[1, 1] == 0 and basin.mask.all()
    assert basin.area == pytest.approx(9 * basin.grid.cell_area)


def test_phase_of_the_schedule_is_respected(paper, alternating):
    gait = find_fixed_point(paper, alternating, 2, (-0.8, -0.15))
    other_phase = gait.orbit[1]
    assert np.hypot(*(other_phase - gait.orbit[0])) > 0.02
    grid = BasinGrid((other_phase[0] - 1e-3, other_phase[0] + 1e-3), (other_phase[1] - 1e-3, other_phase[1] + 1e-3), 2)
    basin = compute_basin(paper, alternating, gait, grid)
    # A state of the orbit's second jump, started with the first leg, is not yet on the gait.
    assert (basin.jumps_to_converge != 0).all()


def test_more_retraction_gives_a_larger_basin(paper):
    """Paper Fig. 8: more stored energy, larger basin (same window for both)."""
    grid = BasinGrid((-2.6, -0.05), (-1.8, 1.6), 40)
    areas = []
    for zeta0 in (0.84, 0.93):
        schedule = ControlSchedule.from_degrees([(30.0, zeta0)])
        gait = find_fixed_point(paper, schedule, 1, (-1.0, 0.0))
        areas.append(compute_basin(paper, schedule, gait, grid).area)
    assert areas[0] > areas[1] > 0


def test_bad_convergence_test_is_rejected(paper, symmetric, gait):
    grid = BasinGrid((-2.0, -0.1), (-1.0, 1.0), 4)
    with pytest.raises(ParameterError, match=r"^tolerance:"):
        compute_basin(paper, symmetric, gait, grid, tolerance=-1.0)
    with pytest.raises(ParameterError, match=r"^jumps:"):
        compute_basin(paper, symmetric, gait, grid, max_jumps=-3)
