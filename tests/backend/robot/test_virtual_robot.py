"""The virtual robot's radio (backend/robot/virtual.py): it answers a Transmit Request as an XBee does,
the firmware behind it. Its body's climb is the climber's (test_climber.py)."""

import socket
import time

from backend.robot.messages import Ack, Command, Kind, RobotState, decode, encode
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
