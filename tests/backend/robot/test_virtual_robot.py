"""The virtual robot's radio (backend/robot/virtual.py): it answers a Transmit Request as an XBee does,
the firmware behind it. Its body's climb is the climber's (test_climber.py)."""

import socket
import time

from backend.robot.firmware import Firmware
from backend.robot.messages import Ack, Command, Fault, Kind, Leg, RobotState, SetLeg, Telemetry, decode, encode
from backend.robot.virtual import VirtualRobot
from backend.robot.xbee import (
    ROBOT_ADDRESS,
    TX_STATUS,
    FrameParser,
    encode_frame,
    parse_rx_packet,
    parse_tx_status,
    tx_request,
)

FOREIGN = 0x0013A200DEADBEEF  # no such radio in the virtual robot's network


def _request(message, frame_id: int, destination64: int = ROBOT_ADDRESS) -> bytes:
    return encode_frame(tx_request(encode(message), frame_id=frame_id, destination64=destination64))


def _answers(connection: socket.socket, until_status: int, timeout: float = 3.0) -> list:
    """Transmit Statuses and the robot's messages (no TELEMETRY), in arrival order, up to the status
    for frame ``until_status``."""
    parser, out = FrameParser(), []
    deadline = time.monotonic() + timeout
    while not any(getattr(item, "frame_id", None) == until_status for item in out):
        assert time.monotonic() < deadline, f"no transmit status for frame {until_status}: {out}"
        for data in parser.feed(connection.recv(4096)):
            if data[0] == TX_STATUS:
                out.append(parse_tx_status(data))
            elif isinstance(message := decode(parse_rx_packet(data).payload), Ack):
                out.append(message)
    return out


def test_the_radio_answers_transmit_status_as_an_xbee_does():
    robot = VirtualRobot().start()
    try:
        with socket.create_connection(robot.address, timeout=3.0) as connection:
            connection.sendall(
                _request(Command(1, Kind.ARM), frame_id=7)
                + _request(Command(2, Kind.HEARTBEAT), frame_id=0)  # frame id 0: no status wanted
                + _request(Command(3, Kind.ESTOP), frame_id=8, destination64=FOREIGN)
                + _request(Command(4, Kind.HEARTBEAT), frame_id=9)
            )
            answers = _answers(connection, until_status=9)
    finally:
        robot.stop()
    statuses = [(a.frame_id, a.delivery, a.retries) for a in answers if not isinstance(a, Ack)]
    assert statuses == [(7, 0x00, 0), (8, 0x24, 0), (9, 0x00, 0)], "delivered, no retries; no radio at FOREIGN"
    assert not isinstance(answers[0], Ack) and isinstance(answers[1], Ack), "the status comes before the reply"
    assert [a.acked for a in answers if isinstance(a, Ack)] == [1], "HEARTBEAT has no ack, the ESTOP never arrived"
    assert robot.firmware.state == RobotState.ARMED


def _booted_telemetry(connection: socket.socket, timeout: float = 3.0) -> Telemetry:
    """The first TELEMETRY that says the robot booted."""
    parser = FrameParser()
    deadline = time.monotonic() + timeout
    while True:
        assert time.monotonic() < deadline, "no telemetry with BOOTED"
        for data in parser.feed(connection.recv(4096)):
            if data[0] != TX_STATUS:
                message = decode(parse_rx_packet(data).payload)
                if isinstance(message, Telemetry) and message.faults & Fault.BOOTED:
                    return message


def test_the_virtual_robot_powers_up_booted():
    robot = VirtualRobot()
    assert robot.firmware.faults == Fault.BOOTED and robot.firmware.state == RobotState.DISARMED
    robot.server.close()


def test_a_reboot_is_a_fresh_firmware_on_the_same_connection():
    robot = VirtualRobot(firmware=Firmware(heartbeat_timeout=5.0)).start()
    try:
        with socket.create_connection(robot.address, timeout=3.0) as connection:
            connection.sendall(
                _request(Command(1, Kind.ARM), frame_id=1)
                + _request(SetLeg(2, Leg.LEFT, 40.0, 0.85), frame_id=2)
                + _request(Command(3, Kind.START), frame_id=3)
            )
            _answers(connection, until_status=3)
            assert robot.firmware.state == RobotState.RUNNING and robot.firmware.legs[Leg.LEFT] == (40.0, 0.85)
            before = robot.firmware
            robot.reboot(brown_out=True)
            firmware = robot.firmware
            assert firmware is not before and firmware.state == RobotState.DISARMED
            assert firmware.faults == Fault.BOOTED | Fault.BROWNOUT
            assert firmware.legs == Firmware().legs, "the legs at their power-up defaults"
            assert firmware.heartbeat_timeout == 5.0, "its configuration kept"
            telemetry = _booted_telemetry(connection)
            assert telemetry.seq <= 3 and telemetry.state == RobotState.DISARMED, "its sequence begins again"
            connection.sendall(_request(Command(4, Kind.ARM), frame_id=4))
            assert [a.acked for a in _answers(connection, until_status=4) if isinstance(a, Ack)] == [4]
            assert robot.firmware.state == RobotState.ARMED, "the same connection reaches the new firmware"
    finally:
        robot.stop()


def test_a_reboot_stops_the_body():
    tracker = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    tracker.bind(("127.0.0.1", 0))
    # A long watchdog: this PC sends no heartbeats, and the first launch may take a while on a busy machine.
    robot = VirtualRobot(firmware=Firmware.boot(heartbeat_timeout=60.0), tracker_to=tracker.getsockname(), speed=4.0)
    robot.start()
    try:
        with socket.create_connection(robot.address, timeout=3.0) as connection:
            start = _request(Command(1, Kind.ARM), frame_id=1) + _request(Command(2, Kind.START), frame_id=2)
            connection.sendall(start)
            _answers(connection, until_status=2)
            deadline = time.monotonic() + 30.0
            while robot.climber.frames_sent < 20:
                assert time.monotonic() < deadline, "the body never moved"
                time.sleep(0.01)
            robot.reboot()
            time.sleep(0.1)  # a frame under way goes out
            sent = robot.climber.frames_sent
            time.sleep(0.3)
            assert robot.climber.frames_sent == sent, "the firmware that ran the climb is gone: the body stops"
    finally:
        robot.stop()
        tracker.close()


def test_a_new_pc_is_no_repeat_of_the_last_ones_commands():
    """A service killed and started again begins its sequence afresh: its RESET, the same bytes as
    the last service's RESET a moment before, is a new command (found: the robot answered it from
    its repeat memory, applied nothing, and stayed e-stopped). The PC starts each link at a random
    seq; the radio's new association clears the memory too, shown here with equal seqs."""
    from backend.robot.link import RobotLink

    robot = VirtualRobot().start()
    try:
        for _ in range(2):
            link = RobotLink(robot.url)
            link._seq = 0  # both links as a PC that always began at 1 would
            link.connect()
            link.estop()
            link.reset()
            assert robot.firmware.state == RobotState.DISARMED
            link.close()
        seqs = {RobotLink(robot.url)._seq for _ in range(8)}
        assert len(seqs) > 1, "each link begins its sequence at a random number"
    finally:
        robot.stop()
