"""The controllers' registry (sim_core/control/registry.py): one entry per law, each designed
and stepped by its own name, and names refused with the choices."""

import math

import numpy as np
import pytest

from sim_core.control.controllers import control_step, new_memory
from sim_core.control.height_controller import HeightController
from sim_core.control.laws import DesignRequest
from sim_core.control.registry import KINDS, LAWS, NAMES, check_names, design, law_kind
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError

MODEL = get_preset("paper").to_model()
REQUEST = DesignRequest(MODEL, HeightController(target=1.2, zeta0_hover=0.95), 35.0)


def test_every_law_has_its_own_name_and_compiled_branch():
    assert tuple(LAWS) == NAMES and len(set(NAMES)) == len(NAMES)
    numbers = [law.number for law in LAWS.values()]
    assert sorted(numbers) == list(range(len(numbers))), "the compiled dispatch's branches, each once"
    assert {law.name: law.number for law in LAWS.values()} == KINDS
    assert all(law.summary and "\n" not in law.summary for law in LAWS.values())


@pytest.mark.parametrize("name", NAMES)
def test_a_designed_law_carries_its_name_and_number_to_the_loop(name):
    law = design(name, REQUEST)
    kind, parameters = law.kernel_args()
    assert law.name == name and kind == LAWS[name].number
    memory = new_memory(kind, math.radians(35.0), 0.95)
    psi0, zeta0, _ = control_step(kind, parameters, memory, 1.0, 0.0, -0.9, -0.2, True)
    assert 0.8 - 1e-12 <= zeta0 <= 0.98 + 1e-12 and np.isfinite(psi0)
    if not LAWS[name].sets_leg_angle:
        assert psi0 == pytest.approx(math.radians(35.0)), "a law that leaves the leg angle gives the nominal one"


def test_an_unknown_name_is_refused_naming_the_field_and_the_choices():
    with pytest.raises(ParameterError) as raised:
        law_kind("mpc", "--controller")
    assert raised.value.field == "--controller" and all(name in str(raised.value) for name in NAMES)
    with pytest.raises(ParameterError, match="twice"):
        check_names(["pid", "pid"])
    with pytest.raises(ParameterError, match="at least one"):
        check_names([])
    assert check_names(["lqr", "pid"]) == ("lqr", "pid")
