"""The height controller's parameters: validation naming the field; a light module."""

import math
import subprocess
import sys

import pytest

from sim_core import ParameterError
from sim_core.control.height_controller import HeightController


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"kp": -1.0}, "kp"),
        ({"target": math.inf}, "target"),
        ({"zeta0_min": 0.95, "zeta0_max": 0.9}, "zeta0_max"),
        ({"zeta0_hover": 0.5}, "zeta0_hover"),
    ],
)
def test_bad_controllers_are_rejected(options, field):
    settings = {"target": 2.0, "zeta0_hover": 0.96} | options
    with pytest.raises(ParameterError, match=f"^{field}:"):
        HeightController(**settings)


def test_defaults_are_the_scanned_gains_inside_the_legs_range():
    controller = HeightController(2.0, 0.96)
    assert (controller.kp, controller.ki, controller.kd) == (0.04, 0.0, 0.02)
    assert controller.zeta0_min < controller.zeta0_hover < controller.zeta0_max


def test_the_controller_loads_no_kernels():
    probe = "import sys, sim_core.control.height_controller; print('numba' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    light = "sim_core.control.height_controller must stay light: the CLI reads its defaults"
    assert result.stdout.strip() == "False", light
