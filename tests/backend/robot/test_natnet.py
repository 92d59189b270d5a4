"""NatNet messages (backend/robot/natnet.py): the header, the versions known, the bounded reader, and
the client's conversation with the server (connect, keep-alive, the server's answer)."""

import struct

import pytest

from backend.robot.natnet import (
    KNOWN_VERSIONS,
    NAT_FRAMEOFDATA,
    NatNetError,
    Reader,
    connect_request,
    decode_server_info,
    format_version,
    is_known,
    keep_alive,
    message_id,
    parse_version,
    payload,
)
from sim_core.model.errors import ParameterError
from tests.backend.robot.natnet_frames import server_info_packet


def test_server_info_and_requests():
    old = decode_server_info(server_info_packet("Tracking Tools", (2, 5, 0, 0), (2, 5, 0, 0)))
    new = decode_server_info(server_info_packet("Motive", (3, 1, 0, 0), (4, 1, 0, 0)))
    assert (old.application, old.natnet_version) == ("Tracking Tools", (2, 5, 0, 0))
    assert (new.application, new.application_version, new.natnet_version) == ("Motive", (3, 1, 0, 0), (4, 1, 0, 0))
    with pytest.raises(NatNetError):
        decode_server_info(server_info_packet("Motive", (3, 1, 0, 0), (4, 1, 0, 0))[:-1])
    request = connect_request((4, 1))
    assert struct.unpack_from("<HH", request) == (0, 271) and len(request) == 275
    assert request[4:8] == b"Ping" and request[4 + 265 : 4 + 269] == bytes([4, 1, 0, 0])
    assert connect_request()[4 + 265 : 4 + 269] == bytes(4), "zeros: the server's own version"
    assert keep_alive() == struct.pack("<HH", 10, 0) + b"\0"


@pytest.mark.parametrize(
    ("text", "ok"),
    [("2.5", (2, 5)), ("4.1", (4, 1)), ("4.2", (4, 2)), ("1.9", None), ("5.0", None), ("3", None), ("x.1", None)],
)
def test_versions_are_checked(text, ok):
    if ok:
        assert parse_version(text) == ok
    else:
        with pytest.raises(ParameterError, match="natnet_version"):
            parse_version(text)


@pytest.mark.parametrize(
    ("version", "known"),
    [((1, 9), False), ((2, 0), True), ((3, 7), True), ((4, 1), True), ((4, 9), True), ((5, 0), False)],
)
def test_known_versions_run_from_2_0_to_any_4_x(version, known):
    assert is_known(version) is known
    assert KNOWN_VERSIONS == "2.0 to 4.x" and format_version((2, 11)) == "2.11"


def test_a_header_names_the_message_and_must_match_what_follows():
    message = struct.pack("<HH", NAT_FRAMEOFDATA, 3) + b"abc"
    assert message_id(message) == NAT_FRAMEOFDATA
    assert bytes(payload(message, NAT_FRAMEOFDATA).data[4:]) == b"abc"
    with pytest.raises(NatNetError, match="4-byte header, got 3 bytes"):
        message_id(message[:3])
    with pytest.raises(NatNetError, match="message id 7, expected 1"):
        payload(message, 1)
    with pytest.raises(NatNetError, match="the header says 3 bytes follow, the packet has 4"):
        payload(message + b"d", NAT_FRAMEOFDATA)


def test_the_reader_names_what_a_short_packet_lacks():
    reader = Reader(struct.pack("<I", 2) + b"name\0" + b"xy")
    assert reader.count("marker", 1) == 2 and reader.offset == 4
    reader.name("marker set name")
    assert (reader.offset, reader.left) == (9, 2)
    with pytest.raises(NatNetError, match="truncated at byte 9: timestamp needs 4, 2 left"):
        reader.u32("timestamp")
    with pytest.raises(NatNetError, match="truncated at byte 9: markers needs 3, 2 left"):
        reader.skip(3, "markers")
    with pytest.raises(NatNetError, match="has no terminating zero"):
        reader.name("device name")
    assert reader.offset == 9, "a refused read moves nothing"


def test_a_count_that_cannot_fit_is_refused_before_anything_loops_over_it():
    reader = Reader(struct.pack("<I", 1_000_000) + bytes(12))
    with pytest.raises(NatNetError, match="rigid body count 1000000 cannot fit in the 12 bytes left"):
        reader.count("rigid body", 12)


def test_a_server_info_must_be_one_whole_message():
    info = server_info_packet("Motive", (3, 1, 0, 0), (3, 1, 0, 0))
    assert decode_server_info(info).natnet_version == (3, 1, 0, 0)
    with pytest.raises(NatNetError, match="not a server info message"):
        decode_server_info(struct.pack("<HH", 5, len(info) - 4) + info[4:])
    with pytest.raises(NatNetError, match="truncated at byte 0: header"):
        decode_server_info(b"\x01")
    with pytest.raises(NatNetError, match="server info needs 264"):
        decode_server_info(struct.pack("<HH", 1, 10) + bytes(10))
