"""The link keeps time whatever the service's interpreter does, and not a moment longer than its lease.

The robot (in a process of its own, :mod:`tests.robot_elsewhere`) disarms itself after 350 ms
without a frame from the PC — the bound the heartbeat's cadence must keep. This interpreter then
holds its GIL, as a compiled kernel called from a live run, a JSON encoder or any C call does for
its whole length (here a C call that sleeps without letting go of it).

- Held for 0.5 s: the link's heartbeat thread (in-process port) cannot run, and the robot disarms
  itself — the finding; through a radio process the heartbeats go on, and the robot stays armed.
- Held for 1.5 s, longer than the lease (0.5 s): the radio process stops the heartbeats as the
  lease runs out, and the robot disarms itself: a service that stops stops the robot.
"""

import time

import pytest

from backend.robot.link import RobotLink
from backend.robot.messages import Fault, RobotState
from backend.robot.radio_process import LEASE
from tests.robot_elsewhere import RobotElsewhere, hold_the_gil

pytestmark = pytest.mark.realtime

WATCHDOG = 0.35  # [s] the robot's: the heartbeat gaps the issue measured against
SHORT_HOLD = 0.5  # [s] longer than the watchdog, shorter than the lease
LONG_HOLD = LEASE + WATCHDOG + 0.65  # [s] the lease and the watchdog, and a margin for the radio process' wake-up


def armed_after_hold(radio_process: bool, hold: float):
    """Connect to a robot elsewhere, arm it, hold the GIL for ``hold`` [s]; the robot's firmware after."""
    with RobotElsewhere(heartbeat_timeout=WATCHDOG) as robot:
        link = RobotLink(robot.url, radio_process=radio_process)
        try:
            link.connect(timeout=10.0)
            link.arm()
            time.sleep(0.3)  # the cadence settled (a radio process' lease is full)
            held = hold_the_gil(hold)
            time.sleep(0.05)  # the robot's answer to the last frames read
            return robot.firmware(), held
        finally:
            link.close()


@pytest.mark.parametrize(("radio_process", "stays_armed"), [(False, False), (True, True)], ids=["thread", "process"])
def test_a_held_interpreter_starves_the_heartbeat_thread_but_not_the_radio_process(radio_process, stays_armed):
    firmware, held = armed_after_hold(radio_process, SHORT_HOLD)
    assert held >= SHORT_HOLD
    if stays_armed:
        assert firmware.state == RobotState.ARMED and not firmware.faults & Fault.HEARTBEAT_LOST, (firmware, held)
    else:  # the finding, as it stands with the port in the service's interpreter
        assert firmware.state == RobotState.DISARMED and firmware.faults & Fault.HEARTBEAT_LOST, (firmware, held)


def test_a_service_held_longer_than_its_lease_stops_the_robot():
    firmware, held = armed_after_hold(True, LONG_HOLD)
    assert held >= LONG_HOLD
    assert firmware.state == RobotState.DISARMED and firmware.faults & Fault.HEARTBEAT_LOST, (firmware, held)
