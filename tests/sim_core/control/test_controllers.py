"""The controllers' one interface (sim_core/control/controllers.py): the PID law as before, the pitch fed
to the next leg with the sign of its wall, the leg's range kept and clipping reported."""

import math

import numpy as np
import pytest

from sim_core.control.closed_loop import pid_step
from sim_core.control.controllers import control_step, new_memory
from sim_core.control.height_controller import HeightController
from sim_core.control.laws import LQR, PID, PID_PITCH, Lqr, Pid

HEIGHT = HeightController(target=1.2, zeta0_hover=0.9)


def _step(law: Pid, memory, height, pitch, next_on_left):
    kind, parameters = law.kernel_args()
    return control_step(kind, parameters, memory, height, pitch, -0.9, -0.3, next_on_left)


def test_the_pid_is_the_height_law_and_holds_the_leg_angle():
    law = Pid(HEIGHT, 35.0)
    memory = new_memory(PID, 0.6, 0.9)
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
    """The left wall's leg meets it at psi0 + pitch, the right's at psi0 - pitch (docs/model.md §5.1):
    the command takes that back, so the leg meets the wall at the nominal angle."""
    law = Pid(HEIGHT, 35.0, pitch_feedback=True)
    pitch = math.radians(3.0)
    psi0, _, clipped = _step(law, new_memory(PID, 0.6, 0.9), 1.2, pitch, next_on_left)
    assert psi0 == pytest.approx(math.radians(35.0) + sign * pitch) and not clipped
    assert law.kernel_args()[0] == PID_PITCH and law.name == "pid-pitch"
    assert _step(law, new_memory(PID, 0.6, 0.9), 1.2, math.nan, next_on_left)[0] == math.radians(35.0), (
        "no pitch tracked"
    )


def test_commands_stay_in_the_legs_range_and_clipping_is_reported():
    law = Pid(HEIGHT, 35.0, pitch_feedback=True, psi0_range_deg=(30.0, 40.0))
    psi0, _, clipped = _step(law, new_memory(PID, 0.6, 0.9), 1.2, math.radians(20.0), True)
    assert psi0 == pytest.approx(math.radians(30.0)) and clipped
    _, zeta0, clipped = _step(law, new_memory(PID, 0.6, 0.9), -5.0, 0.0, True)  # far below: the most retraction
    assert zeta0 == HEIGHT.zeta0_min and clipped


def test_memory_starts_without_an_error_before_or_with_the_first_controls():
    memory = new_memory(PID, 0.6, 0.9)
    assert memory[0] == 0.0 and np.isnan(memory[1])
    assert tuple(new_memory(LQR, 0.6, 0.9)) == (0.6, 0.9)


def _lqr(**changes):
    gain = tuple(0.1 * (k + 1) * (-1) ** k for k in range(10))
    fields = {"target": 2.0, "psi0_deg": 35.0, "zeta0": 0.95, "state": (-0.88, -0.47), "gain": gain} | changes
    return Lqr(**fields)


def test_the_lqr_commands_the_gait_less_its_gain_times_the_state():
    """u_next = u* - K x, x = (section state - the gait's, height - target, last command - u*);
    the command is remembered as the next step's last command, before the pitch turns it."""
    law = _lqr()
    kind, parameters = law.kernel_args()
    memory = new_memory(kind, math.radians(36.0), 0.93)
    x = np.array([-0.9 + 0.88, -0.4 + 0.47, 1.95 - 2.0, math.radians(1.0), 0.93 - 0.95])
    expected = np.array([math.radians(35.0), 0.95]) - np.array(law.gain).reshape(2, 5) @ x
    psi0, zeta0, clipped = control_step(kind, parameters, memory, 1.95, 0.0, -0.9, -0.4, True)
    assert (psi0, zeta0) == pytest.approx(tuple(expected), abs=1e-12) and not clipped
    assert tuple(memory) == pytest.approx(tuple(expected), abs=1e-12)
    turned, _, _ = control_step(kind, parameters, memory, 1.95, math.radians(2.0), -0.9, -0.4, False)
    assert turned == pytest.approx(memory[0] + math.radians(2.0)), "the right wall's leg: turned back by +pitch"


def test_the_lqr_clips_the_error_and_the_state_and_reports_clipped_commands():
    law = _lqr(error_clip=0.2, state_clip=0.05)
    kind, parameters = law.kernel_args()
    far = control_step(kind, parameters, new_memory(kind, math.radians(35.0), 0.95), -50.0, 0.0, -0.88, -0.47, True)
    near = control_step(kind, parameters, new_memory(kind, math.radians(35.0), 0.95), 1.8, 0.0, -0.88, -0.47, True)
    assert far[:2] == near[:2], "an error past the clip acts as the clip"
    fast = control_step(kind, parameters, new_memory(kind, math.radians(35.0), 0.95), 2.0, 0.0, -0.5, -0.47, True)
    edge = control_step(kind, parameters, new_memory(kind, math.radians(35.0), 0.95), 2.0, 0.0, -0.83, -0.47, True)
    assert fast[:2] == edge[:2], "a state deviation past the clip acts as the clip"
    wild = _lqr(gain=(0.0,) * 5 + (100.0,) + (0.0,) * 4)  # zeta0 leaps with xdot
    kind, parameters = wild.kernel_args()
    _, zeta0, clipped = control_step(kind, parameters, new_memory(kind, 0.6, 0.95), 2.0, 0.0, -0.98, -0.47, True)
    assert zeta0 == wild.zeta0_range[1] and clipped
