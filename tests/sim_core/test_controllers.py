"""The controllers' one interface (sim_core/controllers.py): the PID law as before, the pitch fed
to the next leg with the sign of its wall, the leg's range kept and clipping reported."""

import math

import numpy as np
import pytest

from sim_core.closed_loop import pid_step
from sim_core.control_laws import PID, PID_PITCH, Pid
from sim_core.controllers import control_step, new_memory
from sim_core.height_controller import HeightController

HEIGHT = HeightController(target=1.2, zeta0_hover=0.9)


def _step(law: Pid, memory, height, pitch, next_on_left):
    kind, parameters = law.kernel_args()
    return control_step(kind, parameters, memory, height, pitch, next_on_left)


def test_the_pid_is_the_height_law_and_holds_the_leg_angle():
    law, memory = Pid(HEIGHT, 35.0), new_memory()
    integral, previous = 0.0, math.nan
    for height in (1.0, 1.1, 1.25, 1.19):
        psi0, zeta0, clipped = _step(law, memory, height, 0.05, True)
        expected, integral = pid_step(1.2 - height, previous, integral, 0.9, HEIGHT.kp, HEIGHT.ki, HEIGHT.kd,
                                      HEIGHT.zeta0_min, HEIGHT.zeta0_max)  # fmt: skip
        previous = 1.2 - height
        assert (psi0, zeta0, clipped) == (math.radians(35.0), expected, False)
    assert law.kernel_args()[0] == PID and law.name == "pid"


@pytest.mark.parametrize(("next_on_left", "sign"), [(True, -1.0), (False, 1.0)])
def test_pitch_feedback_turns_the_next_leg_back_by_the_pitch_its_wall_adds(next_on_left, sign):
    """The left wall's leg meets it at psi0 + pitch, the right's at psi0 - pitch (model.md §5.1):
    the command takes that back, so the leg meets the wall at the nominal angle."""
    law = Pid(HEIGHT, 35.0, pitch_feedback=True)
    pitch = math.radians(3.0)
    psi0, _, clipped = _step(law, new_memory(), 1.2, pitch, next_on_left)
    assert psi0 == pytest.approx(math.radians(35.0) + sign * pitch) and not clipped
    assert law.kernel_args()[0] == PID_PITCH and law.name == "pid-pitch"
    assert _step(law, new_memory(), 1.2, math.nan, next_on_left)[0] == math.radians(35.0), "no pitch tracked"


def test_commands_stay_in_the_legs_range_and_clipping_is_reported():
    law = Pid(HEIGHT, 35.0, pitch_feedback=True, psi0_range_deg=(30.0, 40.0))
    psi0, _, clipped = _step(law, new_memory(), 1.2, math.radians(20.0), True)
    assert psi0 == pytest.approx(math.radians(30.0)) and clipped
    _, zeta0, clipped = _step(law, new_memory(), -5.0, 0.0, True)  # far below: the most retraction
    assert zeta0 == HEIGHT.zeta0_min and clipped


def test_memory_starts_without_an_error_before():
    memory = new_memory()
    assert memory[0] == 0.0 and np.isnan(memory[1])
