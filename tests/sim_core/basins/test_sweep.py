"""Energy sweeps: continuation, the paper's Fig. 8 trends, the zeta0 of jumping in place."""

import math

import numpy as np
import pytest

from sim_core import ControlSchedule, LegControl, ParameterError, find_fixed_point
from sim_core.basins.grid import BasinGrid
from sim_core.basins.sweep import energy_sweep, zeta0_values

PSI0 = math.radians(30.0)


@pytest.fixture(scope="module")
def sweep(paper):
    grid = BasinGrid((-2.6, -0.05), (-1.8, 1.6), 24)
    return energy_sweep(paper, PSI0, zeta0_values(0.82, 0.97, 6), guess=(-0.94, 0.3), basin_grid=grid)


def test_more_retraction_is_more_stable_and_climbs_faster(sweep):
    """Paper Fig. 8 / docs/model.md §5: smaller zeta0 -> smaller max |λ|, faster climbing, larger basin."""
    assert all(point.gait is not None for point in sweep.points)
    assert np.all(np.diff(sweep.max_abs_eigenvalue) > 0)
    assert np.all(np.diff(sweep.climb_per_jump) < 0)
    assert sweep.basin_area[0] > sweep.basin_area[-1]
    assert sweep.max_abs_eigenvalue[0] < 1.0 < sweep.max_abs_eigenvalue[-1]


def test_in_place_zeta0_is_a_root_of_the_climb(paper, sweep):
    (zeta0,) = sweep.in_place_zeta0
    assert 0.94 < zeta0 < 0.97
    gait = find_fixed_point(paper, ControlSchedule.of(LegControl(PSI0, zeta0)), 1, (-0.93, -0.4))
    assert abs(gait.climb_per_period) < 1e-8


def test_continuation_finds_the_same_gait_as_a_fresh_solve(paper, sweep):
    point = sweep.points[3]
    fresh = find_fixed_point(paper, ControlSchedule.of(LegControl(PSI0, point.zeta0)), 1, (-0.9, -0.2))
    np.testing.assert_allclose(point.gait.state, fresh.state, atol=1e-9)
    assert point.energy == pytest.approx(paper.alpha * (1 - point.zeta0) ** 2 / 2)


def test_sweep_with_a_fixed_leg_is_period_two(paper):
    fixed = LegControl.from_degrees(30.0, 0.87)
    result = energy_sweep(paper, PSI0, [0.89, 0.9], fixed_leg=fixed, guess=(-0.8, -0.15))
    assert [point.gait.period for point in result.points] == [2, 2]
    assert result.to_dict()["fixed_leg"] == {"psi0_deg": pytest.approx(30.0), "zeta0": 0.87}


@pytest.mark.parametrize(
    ("args", "field"),
    [
        ((0.9, 0.8, 10), "zeta0_range"),
        ((0.8, 1.2, 10), "zeta0_range"),
        ((0.8, 0.9, 1), "steps"),
        ((0.8, 0.9, -4), "steps"),
        ((0.8, 0.9, 10**9), "steps"),
    ],
)
def test_bad_sweep_specs_are_rejected(args, field):
    with pytest.raises(ParameterError, match=f"^{field}:"):
        zeta0_values(*args)


def test_bad_psi0_is_rejected_before_any_work(paper):
    with pytest.raises(ParameterError, match="psi0"):
        energy_sweep(paper, math.radians(95.0), [0.9])
