"""The PIDs as data (sim_core/control/laws/pid.py): their parameters checked, naming the field."""

import pytest

from sim_core.control.height_controller import HeightController
from sim_core.control.laws import Pid
from sim_core.control.registry import KINDS
from sim_core.model.validation import ParameterError

HEIGHT = HeightController(target=1.2, zeta0_hover=0.9)


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"psi0_deg": 70.0}, "psi0_deg"),
        ({"psi0_range_deg": (40.0, 30.0)}, "psi0_range_deg"),
        ({"psi0_range_deg": (0.0, 60.0)}, "psi0_range_deg"),
    ],
)
def test_a_law_out_of_range_names_the_field(changes, field):
    with pytest.raises(ParameterError) as raised:
        Pid(**({"height": HEIGHT, "psi0_deg": 35.0} | changes))
    assert raised.value.field == field


def test_each_law_is_named_by_its_kind():
    assert Pid(HEIGHT, 35.0).name == "pid" and Pid(HEIGHT, 35.0, pitch_feedback=True).name == "pid-pitch"
    assert KINDS == {"pid": 0, "pid-pitch": 1, "lqr": 2, "deadbeat": 3, "placement": 4}
