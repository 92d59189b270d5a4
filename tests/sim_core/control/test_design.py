"""A name made a law (sim_core/control/design.py): each kind with the servos' angle range, the height
loop's zeta0 range and its gains; an unknown name refused naming ``controller``; a law stepped one
touchdown at a time as the compiled step, its memory kept and shown as JSON keeps it."""

import math

import numpy as np
import pytest

from sim_core.basins.sweep import find_in_place_zeta0
from sim_core.control.controllers import control_step, new_memory
from sim_core.control.design import SteppedLaw, design_law, law_holding
from sim_core.control.height_controller import HeightController
from sim_core.control.laws import Deadbeat, Lqr, Pid
from sim_core.control.registry import KINDS
from sim_core.model.controls import LegControl
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError

MODEL = get_preset("paper").to_model()
HEIGHT = HeightController(2.0, 0.96, kp=0.05, kd=0.01, zeta0_min=0.82, zeta0_max=0.97)


@pytest.mark.parametrize(("name", "kind"), [("pid", Pid), ("pid-pitch", Pid), ("lqr", Lqr), ("deadbeat", Deadbeat)])
def test_each_name_is_its_law_within_the_ranges_given(name, kind):
    law = design_law(name, MODEL, HEIGHT, 35.0, psi0_range_deg=(20.0, 50.0))
    assert isinstance(law, kind) and law.name == name and law.psi0_range_deg == (20.0, 50.0)
    assert law.target == HEIGHT.target
    if kind is Pid:
        assert law.height == HEIGHT, "the PIDs take the height loop's gains"
    else:
        assert law.zeta0_range == (0.82, 0.97) and law.zeta0 == HEIGHT.zeta0_hover


def test_an_unknown_name_is_refused_naming_the_controller():
    with pytest.raises(ParameterError) as caught:
        design_law("mpc", MODEL, HEIGHT, 35.0)
    assert caught.value.field == "controller" and all(name in str(caught.value) for name in KINDS)


def test_a_law_holding_a_height_is_about_the_in_place_zeta0():
    law = law_holding("pid", MODEL, 2.0, 33.0, gains=(0.03, 0.001, 0.02), zeta0_range=(0.8, 0.98))
    hover = find_in_place_zeta0(MODEL, math.radians(33.0), zeta0_range=(0.8, 0.98))
    assert law.height == HeightController(2.0, hover, 0.03, 0.001, 0.02, 0.8, 0.98)


def test_a_stepped_law_is_the_compiled_step_with_its_memory_kept():
    law = design_law("pid", MODEL, HEIGHT, 35.0)
    stepped = SteppedLaw(law, LegControl.from_degrees(35.0, 0.9))
    assert stepped.state == [0.0, None], "no error before the first step: NaN shown as None"
    kind, parameters = law.kernel_args()
    memory = new_memory(kind, math.radians(35.0), 0.9)
    for height in (1.0, 1.4, 1.9, 2.1):
        expected = control_step(kind, parameters, memory, height, 0.01, -0.9, -0.2, True)
        assert stepped.step(height, 0.01, -0.9, -0.2, True) == tuple(expected)
    np.testing.assert_array_equal(stepped.memory, memory)
