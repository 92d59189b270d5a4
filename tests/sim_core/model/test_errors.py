"""The errors a user can fix (sim_core.model.errors): messages that name the field, pickled as made (the
service raises them in worker processes), and a module light enough for the error handlers."""

import pickle
import subprocess
import sys

import pytest

from sim_core import ControlSchedule
from sim_core.model.errors import FixedPointNotFound, NoGaitFound, ParameterError


def test_a_parameter_error_leads_with_its_field():
    error = ParameterError("zeta0", "must be in (0, 1), got 1.2")
    assert str(error) == "zeta0: must be in (0, 1), got 1.2"
    assert (error.field, error.message) == ("zeta0", "must be in (0, 1), got 1.2")
    assert isinstance(error, ValueError), "callers that catch ValueError still do"


def test_no_gait_found_says_what_to_do_and_is_a_fixed_point_not_found():
    schedule = ControlSchedule.from_degrees([(30.0, 0.87), (30.0, 0.9)])
    error = NoGaitFound(schedule, 2)
    assert str(error) == "no period-2 gait found for controls 30°:0.87, 30°:0.9; give a starting state explicitly"
    assert isinstance(error, FixedPointNotFound) and isinstance(error, RuntimeError)


@pytest.mark.parametrize(
    "error",
    [
        ParameterError("alpha", "must be in (0, inf), got -1"),
        NoGaitFound(ControlSchedule.from_degrees([(80.0, 0.99)]), 1),
        FixedPointNotFound("residual 1e-3 after 400 map evaluations"),
    ],
    ids=["parameter", "no-gait", "not-found"],
)
def test_errors_survive_a_trip_between_processes(error):
    back = pickle.loads(pickle.dumps(error))
    assert type(back) is type(error) and str(back) == str(error)
    assert vars(back) == vars(error), "field, message, schedule and period come back too"


def test_importing_the_errors_loads_no_kernels():
    code = "import sys, sim_core.model.errors; print(sorted({'numba', 'scipy'} & set(sys.modules)))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"
