"""The generated DOP853 step against scipy's own step and error estimate."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import DOP853
from scipy.integrate._ivp.rk import rk_step

from sim_core.model._dop853 import dop853_step
from sim_core.model.stance_equations import PSI, STATE_SIZE, TIME, ZETA, rates

ROOT = Path(__file__).resolve().parents[3]  # tests/sim_core/model/ -> the checkout
PARAMS = (77.6, 0.3, 0.2)  # alpha, c_zeta, c_psi


def test_generated_file_is_up_to_date():
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "generate_dop853.py"), "--check"], capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr


def _state(zeta, psi, zeta_dot, psi_dot, time=0.3):
    return (zeta, psi, zeta_dot, psi_dot, math.cos(psi), math.sin(psi), time)


@pytest.mark.parametrize("independent", [TIME, ZETA, PSI])
@pytest.mark.parametrize("h", [0.05, -0.02])
def test_step_matches_scipy(independent, h):
    state = _state(0.9, 0.4, 0.7, -1.3)

    def fun(_s, y):
        return np.array(rates(tuple(y), *PARAMS, independent))

    y = np.array(state)
    rate = rates(state, *PARAMS, independent)
    solver = DOP853(fun, 0.0, y, t_bound=1.0, rtol=1e-11, atol=1e-11)
    stages = np.empty((solver.n_stages + 1, STATE_SIZE))
    expected_state, expected_rate = rk_step(fun, 0.0, y, np.array(rate), h, solver.A, solver.B, solver.C, stages)
    scale = 1e-11 + 1e-11 * np.maximum(np.abs(y), np.abs(expected_state))
    expected_error = solver._estimate_error_norm(stages, h, scale)

    new_state, new_rate, error = dop853_step(state, rate, h, *PARAMS, independent, 1e-11, 1e-11)

    np.testing.assert_allclose(new_state, expected_state, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(new_rate, expected_rate, rtol=1e-13, atol=1e-14)
    # The estimate is a difference of nearly equal stage sums: summation order moves its last digits.
    assert error == pytest.approx(expected_error, rel=1e-4)
