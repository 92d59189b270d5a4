"""The XBee API-frame codec against Digi's byte examples, and a parser that never breaks."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from backend.robot.xbee import (
    FrameError,
    FrameParser,
    TransmitLog,
    TransmitStatus,
    checksum,
    encode_frame,
    parse_rx_packet,
    parse_tx_request,
    parse_tx_status,
    rx_packet,
    tx_request,
    tx_status,
)

# Digi's documented examples: an AT command (ATNI) and a Transmit Request "TxData0A".
ATNI = bytes.fromhex("7E 00 04 08 01 4E 49 5F")
TX_DATA = bytes.fromhex("10 01 00 13 A2 00 40 0A 01 27 FF FE 00 00 54 78 44 61 74 61 30 41")


def test_unescaped_example_frames():
    assert checksum(ATNI[3:-1]) == 0x5F
    assert encode_frame(ATNI[3:-1]) == ATNI


def test_transmit_request_example_with_escaped_checksum():
    # Checksum 0x13 (XOFF); in escaped mode both 0x13 bytes — in the address and the checksum —
    # travel as 0x7D 0x33.
    assert checksum(TX_DATA) == 0x13
    assert encode_frame(TX_DATA) == bytes.fromhex(
        "7E 00 16 10 01 00 7D 33 A2 00 40 0A 01 27 FF FE 00 00 54 78 44 61 74 61 30 41 7D 33"
    )
    assert FrameParser().feed(encode_frame(TX_DATA)) == [TX_DATA]
    assert tx_request(b"TxData0A", frame_id=1, destination64=0x0013A200400A0127) == TX_DATA
    assert parse_tx_request(TX_DATA) == (1, 0x0013A200400A0127, b"TxData0A")


def test_digi_escape_example():
    # Digi: frame data 0x23 0x11 is sent as 7E 00 02 23 7D 31 CB.
    assert encode_frame(bytes((0x23, 0x11))) == bytes.fromhex("7E 00 02 23 7D 31 CB")
    assert FrameParser().feed(bytes.fromhex("7E 00 02 23 7D 31 CB")) == [bytes((0x23, 0x11))]


def test_receive_packet_round_trip():
    data = rx_packet(b"\x01\x06\x00\x07", source64=0x0013A20040AABBCC)
    received = parse_rx_packet(data)
    assert received.source64 == 0x0013A20040AABBCC and received.payload == b"\x01\x06\x00\x07"


def test_transmit_status_decodes_field_by_field():
    # Frame id 1 delivered to 16-bit address 0xFFFE, no retries, no discovery: 7E 00 07 8B 01 FF FE 00 00 00 76.
    wire = bytes.fromhex("7E 00 07 8B 01 FF FE 00 00 00 76")
    (data,) = FrameParser().feed(wire)
    assert parse_tx_status(data) == TransmitStatus(1, 0xFFFE, 0, 0x00, 0x00)
    assert encode_frame(tx_status(1)) == wire
    failed = parse_tx_status(tx_status(0x47, delivery=0x24, retries=3, discovery=0x02, destination16=0x1234))
    assert failed == TransmitStatus(0x47, 0x1234, 3, 0x24, 0x02)
    assert not failed.delivered and failed.delivery_name == "address not found (0x24)"
    assert parse_tx_status(tx_status(2, delivery=0x99)).delivery_name == "unknown (0x99)"


@pytest.mark.parametrize(
    "data",
    [b"", tx_status(1)[:-1], tx_status(1) + b"\x00", rx_packet(b"\x01\x06\x00\x07", source64=1), b"\x89\x01\x00"],
    ids=["empty", "short", "long", "receive packet", "802.15.4 status"],
)
def test_transmit_status_refuses_other_frames(data):
    with pytest.raises(FrameError, match="not a transmit status"):
        parse_tx_status(data)


def test_frame_ids_cycle_and_are_never_zero():
    log = TransmitLog()
    ids = [log.next_frame_id() for _ in range(600)]
    assert ids[:3] == [1, 2, 3] and ids[254:257] == [255, 1, 2] and 0 not in ids


def test_transmit_log_tallies_statuses():
    log = TransmitLog()
    assert log.last_failure is None
    for delivery, retries in [(0x00, 0), (0x24, 2), (0x00, 1), (0x21, 0)]:
        log.heard(parse_tx_status(tx_status(1, delivery=delivery, retries=retries)))
    assert (log.statuses, log.failures, log.retries) == (4, 2, 3)
    assert log.last_failure == "network ACK failure (0x21)"


def test_parser_resynchronises_and_counts_damage():
    good = encode_frame(b"\x90hello")
    corrupted = bytearray(encode_frame(b"\x90world"))
    corrupted[5] ^= 0xFF
    stream = b"noise" + good[:6] + good + bytes(corrupted) + b"\x7e\x00" + good
    parser = FrameParser()
    frames = [frame for byte in stream for frame in parser.feed(bytes((byte,)))]  # one byte at a time
    assert frames == [b"\x90hello", b"\x90hello"]
    stats = parser.stats
    assert (stats.frames, stats.bad_checksum, stats.truncated, stats.garbage_bytes) == (2, 1, 2, 5)


def test_impossible_length_is_skipped():
    parser = FrameParser()
    assert parser.feed(b"\x7e\xff\xff" + encode_frame(b"\x08ok")) == [b"\x08ok"]
    assert parser.stats.bad_length == 1


@given(st.lists(st.binary(min_size=1, max_size=64), max_size=8), st.binary(max_size=64), st.integers(1, 17))
@settings(max_examples=300, deadline=None)
def test_any_stream_any_chunking(payloads, noise, chunk):
    """Frames survive arbitrary chunking; noise between them never crashes or loses later frames."""
    stream = b"".join(noise.replace(b"\x7e", b"") + encode_frame(payload) for payload in payloads)
    parser = FrameParser()
    frames = []
    for start in range(0, len(stream), chunk):
        frames += parser.feed(stream[start : start + chunk])
    assert frames == payloads


@given(st.binary(max_size=512))
@settings(max_examples=500, deadline=None)
def test_garbage_never_crashes_and_the_link_recovers(garbage):
    parser = FrameParser()
    parser.feed(garbage)
    assert parser.feed(encode_frame(b"\x90after")) == [b"\x90after"], "the next good frame always gets through"


def test_frame_size_is_bounded():
    with pytest.raises(ValueError, match="frame data"):
        encode_frame(b"")
    with pytest.raises(ValueError, match="frame data"):
        encode_frame(bytes(300))
