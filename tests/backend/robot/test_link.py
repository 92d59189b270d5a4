"""The PC's link against the virtual robot over a real TCP socket (pyserial ``socket://``)."""

import socket
import time

import pytest

from backend.robot.firmware import Firmware
from backend.robot.link import WRITE_TIMEOUT, LinkError, LinkState, RobotLink
from backend.robot.messages import Fault, Leg, RobotState
from backend.robot.virtual import VirtualRobot
from sim_core import ParameterError
from tests.helpers import answer_within
from tests.robot_rig import FOREIGN, PtyRobot, received_frame, telemetry

JAMMED_ANSWER_S = 2.0  # [s] "answers instead of hanging": a generous bound, not a latency claim


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
    result = link.estop()
    assert result.acknowledged and result.reason is None
    assert link.state == LinkState.ESTOPPED and robot.firmware.state.name == "ESTOPPED"
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


@pytest.fixture
def jammed():
    """A link on a pty robot (armed, talking) whose PC->robot direction is full: writes block."""
    rig = PtyRobot(RobotState.ARMED).start()
    link = RobotLink(rig.path)
    link.connect()
    rig.jam()
    yield link
    link.close()
    rig.stop()


def test_only_the_robots_radio_is_heard(robot, link):
    link.arm()
    _wait_for(lambda: link.state == LinkState.ARMED)
    robot.inject(received_frame(telemetry(9, RobotState.DISARMED), source64=FOREIGN) * 3)
    _wait_for(lambda: link.foreign_frames == 3)
    time.sleep(0.05)  # the robot's own telemetry keeps coming meanwhile
    assert link.state == LinkState.ARMED and link.telemetry.state == RobotState.ARMED
    assert all(t.reason != "telemetry" or t.after != LinkState.DISARMED for t in link.transitions[1:])
    assert link.counters()["foreign_frames"] == 3 and link.counters()["frames_in"] > 3


def test_a_link_to_another_address_hears_nothing(robot):
    with pytest.raises(LinkError, match="no telemetry"):
        RobotLink(robot.url, robot_address=FOREIGN).connect(timeout=0.3)


def test_estop_on_a_jammed_line_answers_promptly_and_says_so(jammed):
    result = answer_within(JAMMED_ANSWER_S, jammed.estop)
    assert not result.acknowledged and "no acknowledgement" in result.reason
    assert jammed.state == LinkState.ARMED, "not acknowledged: the link does not pretend it stopped"
    assert jammed.counters()["estops_unacknowledged"] == 1


def test_a_blocked_write_is_a_counted_link_error(jammed):
    def set_leg():
        with pytest.raises(LinkError, match="jammed"):
            jammed.set_leg(Leg.LEFT, 30.0, 0.9)
        return True

    assert answer_within(JAMMED_ANSWER_S, set_leg)
    assert jammed.write_timeouts >= 1 and jammed.counters()["write_timeouts"] == jammed.write_timeouts
    assert jammed._port.write_timeout == WRITE_TIMEOUT


def test_an_unacknowledged_estop_stops_the_heartbeats(jammed):
    jammed.estop()
    time.sleep(WRITE_TIMEOUT * 1.5)  # a heartbeat already under way when the e-stop began ends
    written = jammed.write_timeouts
    time.sleep(0.6)  # three heartbeat periods
    assert jammed.write_timeouts == written, "no heartbeat tried: the robot's watchdog will disarm it"


def test_both_ends_of_the_virtual_radio_disable_nagle(robot, link):
    _wait_for(lambda: robot._connection is not None)
    for sock in (link._port._socket, robot._connection):
        assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY)


def test_make_safe_disarms_whatever_the_link_believes(robot, link):
    link.arm()
    robot.inject(received_frame(telemetry(9, RobotState.DISARMED)))  # stale: the robot is armed
    _wait_for(lambda: link.state == LinkState.DISARMED)
    assert robot.firmware.state == RobotState.ARMED
    assert link.make_safe() == LinkState.DISARMED and robot.firmware.state == RobotState.DISARMED


def test_make_safe_accepts_an_estopped_robot(robot, link):
    assert link.estop().acknowledged
    assert link.make_safe() == LinkState.ESTOPPED and robot.firmware.state == RobotState.ESTOPPED


def test_make_safe_says_when_it_cannot_confirm(jammed):
    error = answer_within(JAMMED_ANSWER_S, _raises_link_error, jammed.make_safe)
    assert "jammed" in str(error) or "no acknowledgement" in str(error), error
    jammed.close()
    with pytest.raises(LinkError, match="down"):
        jammed.make_safe()


def _raises_link_error(call):
    try:
        call()
    except LinkError as error:
        return error
    pytest.fail(f"{call.__name__} did not raise LinkError")
