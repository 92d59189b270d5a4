"""The quick calls made directly: request bodies in, sim_core's numbers out as JSON, and a run to store."""

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from backend.schemas import (
    FixedPointIn,
    LegIn,
    MapIn,
    ModelIn,
    StateIn,
    TrajectoryIn,
)
from backend.services import quick_calls
from backend.services.provenance import current_code_version
from backend.store.trajectory_blob import unpack_trajectory
from sim_core import FixedPointNotFound, ParameterError, iterate_map, simulate_trajectory
from tests.backend.services.bodies import START, run_body

PERIOD_1 = [LegIn(psi0_deg=30.0, zeta0=0.9)]
PERIOD_1_EIGENVALUE = 0.8486  # |lambda| of the paper's psi0 = 30°, zeta0 = 0.9 gait (test_fixed_points.py)
EIGENVALUE_ATOL = 1e-4
SLIPS = [LegIn(psi0_deg=60.0, zeta0=0.9)]  # slips on the first jump from START
NO_GAIT = [LegIn(psi0_deg=80.0, zeta0=0.9)]  # no period-1 gait anywhere on the search grid


def _strict_json(value) -> object:
    """``value`` through strict JSON (no NaN/Infinity): what the API can send as is."""
    return json.loads(json.dumps(value, allow_nan=False))


def test_map_orbit_is_the_maps_json(paper, symmetric):
    body = MapIn(controls=PERIOD_1, start=START, jumps=5)
    got = quick_calls.map_orbit(body)
    assert got == iterate_map(paper, symmetric, (START.xdot, START.ydot), 5).to_dict()
    assert got["failure"] is None and len(got["states"]) == 6 and len(got["rises"]) == 5


def test_map_orbit_reports_the_failed_jump():
    got = quick_calls.map_orbit(MapIn(controls=SLIPS, start=START, jumps=5))
    assert got["failure"] == {"code": "slip", "jump": 1} and got["states"] == [[START.xdot, START.ydot]]


def test_trajectory_columns_are_the_sampled_path(paper, symmetric):
    body = TrajectoryIn(controls=PERIOD_1, start=START, jumps=2, rate=50.0)
    got = quick_calls.trajectory_columns(body)
    path = simulate_trajectory(paper, symmetric, (START.xdot, START.ydot), 2, sample_rate=50.0)
    assert got == _strict_json(got), "plain JSON already"
    assert got["units"] == "nondimensional" and got["failure"] is None
    assert got["touchdown_times"] == path.touchdown_times.tolist() and len(got["touchdown_times"]) == 3
    assert set(got["columns"]) == set(path.COLUMNS)
    for name, column in path.columns().items():
        assert_array_equal(np.array(got["columns"][name], dtype=float), column, err_msg=name)


def test_trajectory_of_a_failing_climb_says_where_it_failed():
    got = quick_calls.trajectory_columns(TrajectoryIn(controls=SLIPS, start=START, jumps=3))
    assert got["failure"] == {"code": "slip", "jump": 1}
    assert got == _strict_json(got)


def test_fixed_point_from_a_guess():
    gait = quick_calls.fixed_point(FixedPointIn(controls=PERIOD_1, guess=StateIn(xdot=-0.9, ydot=-0.2)))
    assert gait["period"] == 1 and gait["stable"] and gait["motion"] == "climbing"
    assert gait["max_abs_eigenvalue"] == pytest.approx(PERIOD_1_EIGENVALUE, abs=EIGENVALUE_ATOL)
    assert gait["orbit"][0] == gait["state"] and gait == _strict_json(gait)


def test_fixed_point_without_a_guess_searches(alternating):
    searched = quick_calls.fixed_point(FixedPointIn(controls=PERIOD_1))
    guessed = quick_calls.fixed_point(FixedPointIn(controls=PERIOD_1, guess=StateIn(xdot=-0.9, ydot=-0.2)))
    assert searched["state"] == pytest.approx(guessed["state"], abs=1e-9), "one stable gait: the search finds it"
    legs = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]
    assert quick_calls.fixed_point(FixedPointIn(controls=legs))["period"] == len(alternating), "period defaults to m"


def test_fixed_point_errors():
    with pytest.raises(ParameterError) as error:
        quick_calls.fixed_point(FixedPointIn(controls=NO_GAIT))
    assert error.value.field == "controls" and "no period-1 gait" in str(error.value)
    with pytest.raises(FixedPointNotFound):
        quick_calls.fixed_point(FixedPointIn(controls=NO_GAIT, guess=StateIn(xdot=-0.9, ydot=-0.2)))
    with pytest.raises(ParameterError) as error:
        quick_calls.fixed_point(FixedPointIn(controls=PERIOD_1 * 2, period=3, guess=StateIn(xdot=-0.9, ydot=-0.2)))
    assert error.value.field == "period"


def test_simulate_run_gives_the_run_to_store(paper, symmetric):
    run = quick_calls.simulate_run(run_body(0.9, jumps=4, trajectory_rate=40.0))
    orbit = iterate_map(paper, symmetric, (START.xdot, START.ydot), 4)
    assert (run.kind, run.status, run.failure_code, run.jumps_completed) == (
        "sim",
        "done",
        None,
        4,
    )
    assert run.climb == pytest.approx(float(orbit.rises.sum()), rel=1e-12)
    assert run.results == _strict_json(orbit.to_dict()) and "fixed_point" not in run.results
    assert run.model["alpha"] == paper.alpha and run.code_version == current_code_version()
    assert run.duration_s >= 0 and run.controls == [[30.0, 0.9]]
    path = unpack_trajectory(run.trajectory)
    assert set(path) == set(simulate_trajectory(paper, symmetric, (START.xdot, START.ydot), 4).COLUMNS)


def test_simulate_run_stores_infinite_friction_as_null():
    # The API refuses Infinity (strict JSON); a model can still have it (a stored job's, the CLI's).
    run = quick_calls.simulate_run(run_body(model=ModelIn.model_construct(preset="paper", mu=math.inf)))
    assert run.model["mu"] is None and run.trajectory is None
    assert run.model == _strict_json(run.model)


def test_simulate_run_with_the_gait_near_its_start():
    found = quick_calls.simulate_run(run_body(fixed_point=True)).results["fixed_point"]
    assert found["found"] and found["max_abs_eigenvalue"] == pytest.approx(PERIOD_1_EIGENVALUE, abs=EIGENVALUE_ATOL)
    lost = quick_calls.simulate_run(run_body(fixed_point=True, start=StateIn(xdot=-0.3, ydot=5.0)))
    assert lost.failure_code == "no_flight"
    assert lost.results["fixed_point"]["found"] is False and lost.results["fixed_point"]["reason"]
