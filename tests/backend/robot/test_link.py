"""The PC's link against the virtual robot over a real TCP socket (pyserial ``socket://``)."""

import time

import pytest

from backend.robot.firmware import Firmware
from backend.robot.link import LinkError, LinkState, RobotLink
from backend.robot.messages import Fault, Leg
from backend.robot.virtual import VirtualRobot
from sim_core import ParameterError


@pytest.fixture
def robot():
    virtual = VirtualRobot().start()
    yield virtual
    virtual.stop()


@pytest.fixture
def link(robot):
    connection = RobotLink(robot.url, heartbeat_timeout=0.5)
    connection.connect()
    yield connection
    connection.close()


def _wait_for(predicate, timeout=3.0):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def test_connect_arm_command_disarm(robot, link):
    assert link.state == LinkState.DISARMED
    link.arm()
    _wait_for(lambda: link.state == LinkState.ARMED)
    link.set_leg(Leg.RIGHT, 35.0, 0.88)
    assert robot.firmware.legs[Leg.RIGHT] == (35.0, 0.88)
    _wait_for(lambda: link.telemetry.psi_servo_deg[1] == 35.0)
    link.disarm()
    _wait_for(lambda: link.state == LinkState.DISARMED)
    assert [t.after for t in link.transitions] == [LinkState.DISARMED, LinkState.ARMED, LinkState.DISARMED]


def test_commands_beyond_servo_limits_are_refused_before_sending(robot, link):
    with pytest.raises(ParameterError, match=r"^zeta0: must be in \[0.75, 0.98\]"):
        link.set_leg(Leg.LEFT, 30.0, 0.99)
    assert robot.firmware.legs[Leg.LEFT] == (30.0, 0.9), "nothing reached the robot"


def test_estop_latches_until_reset_and_is_fast(robot, link):
    link.arm()
    latency = link.estop()
    assert link.state == LinkState.ESTOPPED and robot.firmware.state.name == "ESTOPPED"
    assert latency < 0.5, f"e-stop acknowledged after {latency * 1000:.0f} ms"
    with pytest.raises(LinkError, match="refused"):
        link.arm()
    link.reset()
    _wait_for(lambda: link.state == LinkState.DISARMED)


def test_robot_disarms_when_heartbeats_stop(robot):
    robot.firmware.heartbeat_timeout = 0.3
    link = RobotLink(robot.url)
    link.connect()
    try:
        link.arm()
        _wait_for(lambda: link.state == LinkState.ARMED)
        link.send_heartbeats = False
        _wait_for(lambda: link.state == LinkState.DISARMED)
        assert link.telemetry.faults & Fault.HEARTBEAT_LOST
    finally:
        link.close()


def test_killing_the_robot_is_a_lost_link(robot):
    link = RobotLink(robot.url, heartbeat_timeout=0.3)
    link.connect()
    reasons = []
    link.on_lost.append(reasons.append)
    robot.stop()
    _wait_for(lambda: link.state == LinkState.DISCONNECTED)
    assert reasons and ("heartbeat" in reasons[0] or "read failed" in reasons[0])
    with pytest.raises(LinkError, match="down"):
        link.arm()
    link.close()


def test_unreachable_robot_is_a_clear_error():
    with pytest.raises(LinkError, match="cannot open"):
        RobotLink("socket://127.0.0.1:9").connect(timeout=0.5)


def test_firmware_rules_without_a_network():
    firmware = Firmware(heartbeat_timeout=0.5)
    firmware.receive(
        __import__("backend.robot.messages", fromlist=["Command"]).Command(
            1, __import__("backend.robot.messages", fromlist=["Kind"]).Kind.ARM
        ),
        0.0,
    )
    assert firmware.state.name == "ARMED"
    firmware.tick(0.4)
    assert firmware.state.name == "ARMED"
    firmware.tick(0.6)
    assert firmware.state.name == "DISARMED" and firmware.faults & Fault.HEARTBEAT_LOST
