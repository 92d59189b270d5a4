"""The link's port: frames whole, ids in order, a closed port says so, a bad URL names itself."""

import pytest

from backend.robot.link_port import LinkPort
from backend.robot.link_types import LinkError
from backend.robot.messages import Command, Kind, decode
from backend.robot.xbee import ROBOT_ADDRESS, FrameParser, parse_tx_request


def test_messages_go_out_as_frames_to_the_robot_with_ids_in_order():
    port = LinkPort("loop://", 57_600, ROBOT_ADDRESS)
    port.open()
    try:
        for seq in range(1, 4):
            port.write(Command(seq, Kind.HEARTBEAT))
        frames = list(FrameParser().feed(port.read() + port.read()))
    finally:
        port.close()
    assert [parse_tx_request(frame)[0] for frame in frames] == [1, 2, 3] and port.frames_out == 3
    assert [decode(parse_tx_request(frame)[2]).seq for frame in frames] == [1, 2, 3]


def test_a_closed_port_refuses_to_write_and_reads_nothing():
    port = LinkPort("loop://", 57_600, ROBOT_ADDRESS)
    with pytest.raises(LinkError, match="the link is down"):
        port.write(Command(1, Kind.HEARTBEAT))
    assert port.read() == b"" and not port.is_open and port.frames_out == 0


def test_a_port_that_cannot_be_opened_is_named():
    with pytest.raises(LinkError, match=r"cannot open socket://127\.0\.0\.1:1"):
        LinkPort("socket://127.0.0.1:1", 57_600, ROBOT_ADDRESS).open()
