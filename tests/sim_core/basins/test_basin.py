"""Basins of attraction: against the scipy path, the gait's own cell, phases, Fig. 8's trend, and
undecided cells continued up to a jump limit."""

import numpy as np
import pytest

from sim_core import ControlSchedule, ParameterError, find_fixed_point
from sim_core.basins.basin import NOT_CONVERGED, compute_basin
from sim_core.basins.cells import FALLING_SPEED
from sim_core.basins.grid import DEFAULT_BASIN_WINDOW, BasinGrid
from sim_core.model.failures import OK
from sim_core.model.reference import reference_jump


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


@pytest.fixture(scope="module")
def period_2(paper, alternating):
    return find_fixed_point(paper, alternating, 2, (-0.8, -0.15))


def test_undecided_cells_continued_decide_as_one_run_to_the_limit(paper, alternating, period_2):
    """The truth is one run per cell with the larger cap, free of the continuation: cells left
    undecided at 3 jumps go on at jump 3 (an odd one: the right leg's phase) in rounds of 6, 12,
    24 and 40 jumps, and must decide, stop and count jumps exactly as one 40-jump run does."""
    grid = BasinGrid(*DEFAULT_BASIN_WINDOW, 8)
    continued = compute_basin(paper, alternating, period_2, grid, max_jumps=3, jump_limit=40)
    single = compute_basin(paper, alternating, period_2, grid, max_jumps=40)
    np.testing.assert_array_equal(continued.jumps_to_converge, single.jumps_to_converge)
    np.testing.assert_array_equal(continued.failure, single.failure)
    np.testing.assert_array_equal(continued.jumps_run, single.jumps_run)
    np.testing.assert_array_equal(continued.stopped_at, single.stopped_at)
    late = continued.jumps_to_converge > 3
    assert late.any() and (continued.jumps_to_converge[late] % 2 == 1).any(), "cells decided in the later rounds"
    assert [r["cap"] for r in continued.rounds()] == [3, 6, 12, 24, 40]


def test_the_jump_limit_is_honoured_and_the_rounds_add_up(paper, symmetric, gait):
    grid = BasinGrid(*DEFAULT_BASIN_WINDOW, 8)
    basin = compute_basin(paper, symmetric, gait, grid, max_jumps=2, jump_limit=9)
    assert basin.jump_limit == 9 and basin.jumps_run.max() == 9
    assert basin.undecided.any(), "some cells stay undecided at 9 jumps, so the limit binds"
    running = basin.undecided & ~basin.falling
    assert (basin.jumps_run[running] == 9).all() and (basin.jumps_run[~running] <= 9).all()
    # A falling run stops as soon as it falls (past FALLING_SPEED), undecided, and is not continued.
    assert (
        basin.falling.any() and (np.hypot(*np.moveaxis(basin.stopped_at[basin.falling], -1, 0)) > FALLING_SPEED).all()
    )
    assert basin.to_dict()["falling"] == int(basin.falling.sum())
    np.testing.assert_array_equal(basin.undecided, ~basin.mask & (basin.failure == OK))
    rounds = basin.rounds()
    assert [r["cap"] for r in rounds] == [2, 4, 8, 9]
    first_cap = compute_basin(paper, symmetric, gait, grid, max_jumps=2).outcome_counts()
    assert rounds[0] == {"cap": 2, "converged": first_cap["converged"], "undecided": first_cap["not_converged"]}
    assert rounds[-1]["undecided"] == basin.outcome_counts()["not_converged"] == basin.to_dict()["undecided"]
    assert basin.jumps_computed == basin.jumps_run.sum()


def test_without_a_limit_nothing_is_continued(paper, symmetric, gait):
    basin = compute_basin(paper, symmetric, gait, BasinGrid(*DEFAULT_BASIN_WINDOW, 4), max_jumps=5)
    assert basin.jump_limit == 5 and basin.jumps_run.max() <= 5 and len(basin.rounds()) == 1


@pytest.mark.parametrize("limit", [4, -1, 2.5, True, 10**7])
def test_bad_jump_limit_is_rejected(paper, symmetric, gait, limit):
    with pytest.raises(ParameterError, match=r"^jump_limit:"):
        compute_basin(paper, symmetric, gait, BasinGrid((-2.0, -0.1), (-1.0, 1.0), 4), max_jumps=5, jump_limit=limit)
