"""A restart of the robot as the link sees it (backend/robot/link_restarts.py): a TELEMETRY that
carries BOOTED where the one before did not, or whose sequence went back, names a restart."""

import pytest

from backend.robot.link_restarts import BOOT_SEQ, SEQ_WINDOW, restart_reason
from backend.robot.messages import Fault, RobotState, Telemetry

BOOTED = int(Fault.BOOTED)


def _telemetry(seq: int, faults: int = 0) -> Telemetry:
    return Telemetry(seq, RobotState.DISARMED, (30.0, 30.0), (0.9, 0.9), 7400, faults)


def test_the_first_telemetry_heard_is_never_a_restart():
    assert restart_reason(None, _telemetry(2, BOOTED)) is None, "a robot just powered up, before we knew it"


def test_a_boot_after_a_robot_that_had_been_armed_is_a_restart():
    assert restart_reason(_telemetry(4211), _telemetry(3, BOOTED)) == (
        "robot restarted (its sequence went back from 4211 to 3)"
    )
    assert restart_reason(_telemetry(10), _telemetry(12, BOOTED)) == "robot restarted (it reports having just booted)"


def test_a_brown_out_says_so():
    reason = restart_reason(_telemetry(4211), _telemetry(2, BOOTED | Fault.BROWNOUT))
    assert reason == "robot restarted (brown-out; its sequence went back from 4211 to 2)"


def test_a_second_boot_before_any_arm_is_seen_by_the_sequence():
    assert restart_reason(_telemetry(40, BOOTED), _telemetry(41, BOOTED)) is None, "the same boot"
    assert restart_reason(_telemetry(400, BOOTED), _telemetry(2, BOOTED)) == (
        "robot restarted (its sequence went back from 400 to 2)"
    )


@pytest.mark.parametrize(
    ("before", "after"),
    [
        ((SEQ_WINDOW + 2, BOOTED), (2, BOOTED)),  # within the window: a late frame, not a boot
        ((65530, BOOTED), (5, BOOTED)),  # a wrap goes forward
        ((40000, BOOTED), (20000, BOOTED)),  # far back but not near the start: not a boot's sequence
        ((4211, 0), (3, 0)),  # back without BOOTED: a stale or forged frame, not a boot
        ((4211, BOOTED), (4212, 0)),  # BOOTED cleared (the ARM)
    ],
)
def test_what_is_not_a_restart(before, after):
    assert restart_reason(_telemetry(*before), _telemetry(*after)) is None


def test_the_window_and_the_start_bound():
    assert restart_reason(_telemetry(SEQ_WINDOW + 3, BOOTED), _telemetry(2, BOOTED)) is not None
    assert restart_reason(_telemetry(BOOT_SEQ + 500, BOOTED), _telemetry(BOOT_SEQ, BOOTED)) is not None
    assert restart_reason(_telemetry(BOOT_SEQ + 500, BOOTED), _telemetry(BOOT_SEQ + 1, BOOTED)) is None
