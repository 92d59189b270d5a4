"""The LQR as data (sim_core/control/laws/lqr.py): its parameters checked, naming the field."""

import math

import pytest

from sim_core.control.laws import Lqr
from sim_core.model.validation import ParameterError


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"gain": (0.0,) * 9}, "gain"),
        ({"gain": (math.nan,) * 10}, "gain"),
        ({"error_clip": 0.0}, "error_clip"),
        ({"zeta0_range": (0.9, 0.8)}, "zeta0_range"),
        ({"psi0_deg": 5.0}, "psi0_deg"),
        ({"target": -1.0}, "target"),
    ],
)
def test_an_lqr_out_of_range_names_the_field(changes, field):
    fields = {"target": 2.0, "psi0_deg": 35.0, "zeta0": 0.95, "state": (-0.88, -0.47), "gain": (0.1,) * 10}
    with pytest.raises(ParameterError) as raised:
        Lqr(**(fields | changes))
    assert raised.value.field == field
