"""The law a live run closes (backend/robot/live_law.py): the PID as today's loop (to rounding), the
model-based laws as the simulator's compiled ones on what the touchdown shows, each command's
journal entry, the pitch read at the touchdown, and a law the servos cannot follow refused."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from backend.robot.limits import ServoLimits
from backend.robot.live_law import LiveLaw, live_law_for, pitch_at
from backend.robot.touchdown import PITCH_LOOKBACK, Touchdown
from sim_core.control.closed_loop import pid_step
from sim_core.control.controllers import control_step, new_memory
from sim_core.control.design import design_law
from sim_core.control.height_controller import HeightController
from sim_core.model.controls import LegControl
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError
from sim_core.model.walls import Wall, wall_of

ROBOT = get_preset("paper")
LEGS = [LegControl.from_degrees(35.0, 0.9), LegControl.from_degrees(33.0, 0.91)]
HEIGHTS = (0.12, 0.2, 0.31, 0.38, 0.43, 0.41)  # [m], touchdowns climbing toward a 0.4 m target


def _touchdown(index: int, height: float, state=(-0.9, -0.25)) -> Touchdown:
    return Touchdown(index, 0.3 * index, wall_of(index + 1), state, height, height - 0.1, 12)


def _loop(**changes):
    fields = dict(target_m=0.4, controller="pid", kp=0.04, ki=0.01, kd=0.02, zeta0_min=0.8, zeta0_max=0.98,
                  climb_per_jump=0.5)  # fmt: skip
    return SimpleNamespace(**(fields | changes))


def test_the_pid_is_todays_loop_and_each_leg_keeps_its_angle():
    """Today's loop took the error as (target - height) / l0, the law as target / l0 - height / l0:
    the same to rounding (1e-15), so to 1e-12 here."""
    law = live_law_for(_loop(), ROBOT, LEGS, ServoLimits())
    hover = law.law.height.zeta0_hover
    integral, previous = 0.0, math.nan
    for index, height in enumerate(HEIGHTS):
        leg_psi0 = LEGS[index % 2].psi0
        control, journal = law.command(_touchdown(index, height), math.radians(1.0), leg_psi0)
        error = (0.4 - height) / ROBOT.leg_length
        expected, integral = pid_step(error, previous, integral, hover, 0.04, 0.01, 0.02, 0.8, 0.98)
        previous = error
        assert control.psi0 == leg_psi0 and control.zeta0 == pytest.approx(expected, rel=1e-12)
        assert journal["controller"] == "pid" and journal["clipped"] == (expected in (0.8, 0.98))
        assert journal["state"] == pytest.approx([integral, error], rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("name", ["pid-pitch", "lqr", "deadbeat", "placement"])
def test_a_model_based_law_is_the_simulators_on_what_the_touchdown_shows(name):
    """The same compiled law, stepped on the touchdown's height [l0], pitch and section state,
    for the climb's next touchdown's wall; its memory starts at the right leg's controls."""
    law = live_law_for(_loop(controller=name), ROBOT, LEGS, ServoLimits())
    model, hover = ROBOT.to_model(), law.law.zeta0 if name != "pid-pitch" else law.law.height.zeta0_hover
    height = HeightController(0.4 / ROBOT.leg_length, hover, 0.04, 0.01, 0.02, 0.8, 0.98)
    twin = design_law(name, model, height, 35.0)
    kind, parameters = twin.kernel_args()
    memory = new_memory(kind, LEGS[1].psi0, LEGS[1].zeta0)
    rng = np.random.default_rng(3)
    for index, body in enumerate(HEIGHTS):
        state, pitch = (rng.uniform(-1.0, -0.8), rng.uniform(-0.4, -0.1)), rng.normal(0.0, 0.03)
        control, journal = law.command(_touchdown(index, body, state), pitch, 0.0)
        on_left = wall_of(index + 2) == Wall.LEFT
        psi0, zeta0, clipped = control_step(kind, parameters, memory, body / ROBOT.leg_length, pitch, *state, on_left)
        assert (control.psi0, control.zeta0) == (psi0, zeta0)
        assert journal == {"controller": name, "clipped": clipped, "state": [float(value) for value in memory]}


def test_the_laws_angle_stays_within_the_servos_range():
    limits = ServoLimits(psi0_deg=(30.0, 40.0))
    law = live_law_for(_loop(controller="lqr"), ROBOT, LEGS, limits)
    assert law.law.psi0_range_deg == (30.0, 40.0)
    control, journal = law.command(_touchdown(0, 0.1), math.radians(15.0), 0.0)  # a big pitch to take back
    assert control.psi0 == pytest.approx(math.radians(30.0), abs=1e-15) and journal["clipped"]
    limits.check(control.psi0_deg, control.zeta0)  # as sent (0.01°): within the range, however it rounds


@pytest.mark.parametrize(("field", "value"), [("zeta0_min", 0.7), ("zeta0_max", 0.99)])
def test_a_zeta0_range_the_servos_cannot_reach_is_refused_naming_it(field, value):
    with pytest.raises(ParameterError) as caught:
        live_law_for(_loop(**{field: value}), ROBOT, LEGS, ServoLimits())
    assert caught.value.field == f"closed_loop.{field}"


def test_the_pitch_is_the_last_given_at_or_before_the_touchdown():
    time = np.array([0.0, 0.01, 0.02, 0.03, 0.04])
    pitch = np.array([0.1, 0.2, math.nan, math.nan, 0.5])
    assert pitch_at(time, pitch, 0.015) == 0.2
    assert pitch_at(time, pitch, 0.035) == 0.2, "looked back past the poses without one"
    assert pitch_at(time, pitch, 0.04) == 0.5
    # The look-back spans PITCH_LOOKBACK poses, the touchdown's own included.
    far = np.full(PITCH_LOOKBACK + 1, math.nan)
    far[0] = 0.3  # PITCH_LOOKBACK poses before the last
    assert math.isnan(pitch_at(np.arange(far.size) * 0.01, far, 1.0)), "not further than the lookback"
    assert pitch_at(np.arange(far.size - 1) * 0.01, far[:-1], 1.0) == 0.3, "as far as the lookback"
    assert math.isnan(pitch_at(time, np.full(5, math.nan), 0.04))


def test_it_is_compiled_before_the_run_starts():
    law = LiveLaw(0.4, design_law("deadbeat", ROBOT.to_model(), HeightController(1.8, 0.96), 35.0),
                  ROBOT.leg_length, LEGS[1])  # fmt: skip
    assert law.name == "deadbeat" and tuple(law.memory) == (LEGS[1].psi0, LEGS[1].zeta0), "the warm-up left it as new"


def test_a_calibrations_offsets_are_taken_off_each_command_within_the_servos_range():
    """The leg realises command + offset, so the law's choice is sent less its leg's offset; where
    that passes a servo's end the command is held there and counted as clipped."""
    from sim_core.model.controls import LegOffsets

    law = design_law("lqr", ROBOT.to_model(), HeightController(1.8, 0.96), 35.0)
    offsets = LegOffsets(psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
    plain, offset = LiveLaw(0.4, law, ROBOT.leg_length, LEGS[1]), LiveLaw(0.4, law, ROBOT.leg_length, LEGS[1], offsets)
    for index, height in enumerate(HEIGHTS):
        side = (index + 2) % 2  # the next touchdown's leg: 0 left, 1 right
        want, _ = plain.command(_touchdown(index, height), 0.0, 0.0)
        got, _ = offset.command(_touchdown(index, height), 0.0, 0.0)
        assert got.psi0_deg == pytest.approx(want.psi0_deg - offsets.psi0_offset_deg[side], abs=1e-12)
        assert got.zeta0 == pytest.approx(want.zeta0 - offsets.zeta0_offset[side], abs=1e-15)
    at_the_end = LiveLaw(0.4, law, ROBOT.leg_length, LEGS[1], LegOffsets(zeta0_offset=(-0.09, -0.09)))
    control, journal = at_the_end.command(_touchdown(0, 0.1), 0.0, 0.0)
    assert control.zeta0 == ServoLimits().zeta0[1] and journal["clipped"]
