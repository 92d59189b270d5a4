"""Servo limits (backend/robot/limits.py): the range every leg command is checked against, its ends
included, and limits that could not be a servo's refused when they are made."""

import math

import pytest

from backend.robot.limits import ServoLimits
from sim_core.model.errors import ParameterError

LIMITS = ServoLimits()  # psi0 10°–60°, zeta0 0.75–0.98


@pytest.mark.parametrize(("psi0_deg", "zeta0"), [(10.0, 0.75), (60.0, 0.98), (30.0, 0.9)])
def test_commands_within_the_range_ends_included_are_allowed(psi0_deg, zeta0):
    LIMITS.check(psi0_deg, zeta0)
    assert LIMITS.allows(psi0_deg, zeta0)


@pytest.mark.parametrize(
    ("psi0_deg", "zeta0", "field", "says"),
    [
        (9.99, 0.9, "psi0_deg", "must be in [10, 60], got 9.99"),
        (60.01, 0.9, "psi0_deg", "must be in [10, 60]"),
        (30.0, 0.7499, "zeta0", "must be in [0.75, 0.98], got 0.7499"),
        (30.0, 0.981, "zeta0", "must be in [0.75, 0.98]"),
        (math.nan, 0.9, "psi0_deg", "finite"),
        (30.0, math.inf, "zeta0", "finite"),
    ],
)
def test_a_command_outside_the_servos_range_is_refused_naming_the_field(psi0_deg, zeta0, field, says):
    assert not LIMITS.allows(psi0_deg, zeta0)
    with pytest.raises(ParameterError, match=f"^{field}: ") as raised:
        LIMITS.check(psi0_deg, zeta0)
    assert raised.value.field == field and says in raised.value.message


def test_narrower_limits_are_the_ones_held():
    tight = ServoLimits(psi0_deg=(25.0, 35.0), zeta0=(0.85, 0.9))
    assert tight.allows(25.0, 0.9) and not tight.allows(24.9, 0.9) and not tight.allows(30.0, 0.91)
    assert LIMITS.allows(24.9, 0.91), "the defaults are not changed by another instance"


@pytest.mark.parametrize(
    ("limits", "field", "says"),
    [
        ({"psi0_deg": (40.0, 20.0)}, "limits.psi0_deg", "low < high, got [40, 20]"),
        ({"zeta0": (0.9, 0.9)}, "limits.zeta0", "low < high"),
        ({"psi0_deg": (0.0, 60.0)}, "limits.psi0_deg", "must be in (0, 90)"),
        ({"psi0_deg": (10.0, 90.0)}, "limits.psi0_deg", "must be in (0, 90)"),
        ({"zeta0": (0.5, 1.0)}, "limits.zeta0", "must be in (0, 1)"),
    ],
)
def test_limits_no_servo_could_have_are_refused_when_made(limits, field, says):
    with pytest.raises(ParameterError) as raised:
        ServoLimits(**limits)
    assert raised.value.field == field and says in raised.value.message


def test_a_command_is_checked_as_the_message_carries_it():
    """SET_LEG carries 0.01° and 0.0001 l0: a law's 30° that came back from radians as
    29.999999999999996° goes out as 30.00° and is within a range from 30°; a command that would
    go out past the end is refused."""
    tight = ServoLimits(psi0_deg=(30.0, 40.0), zeta0=(0.8, 0.9))
    assert math.degrees(math.radians(30.0)) < 30.0
    tight.check(math.degrees(math.radians(30.0)), 0.9 + 1e-12)
    assert not tight.allows(40.006, 0.85) and not tight.allows(35.0, 0.90006)


def test_a_laws_command_is_held_to_the_range_and_says_so():
    """What both laws send (backend/robot/live_law.py, plan_law.py): inside, as it is; past an end, the end."""
    inside = (math.radians(30.0), 0.9)
    assert LIMITS.held(*inside) == (inside, False)
    (psi0, zeta0), clipped = LIMITS.held(math.radians(75.0), 0.5)
    assert clipped and (math.degrees(psi0), zeta0) == (pytest.approx(60.0), 0.75)
    assert LIMITS.allows(math.degrees(psi0), zeta0)
