"""Application messages: exact bytes, round trips, and malformed payloads refused."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from backend.robot.messages import (
    Ack,
    Command,
    Fault,
    Kind,
    Leg,
    ProtocolError,
    Result,
    RobotState,
    SetLeg,
    Telemetry,
    decode,
    encode,
)
from sim_core.model.walls import Wall


def test_set_leg_bytes():
    # version 1, type 0x01, seq 0x0102, right leg, 30.00 deg = 3000 = 0x0BB8, zeta0 0.9 = 9000 = 0x2328
    assert encode(SetLeg(0x0102, Leg.RIGHT, 30.0, 0.9)) == bytes.fromhex("01 01 0102 01 0BB8 2328")


def test_estop_bytes():
    assert encode(Command(7, Kind.ESTOP)) == bytes.fromhex("01 04 0007")


@pytest.mark.parametrize(
    "message",
    [
        SetLeg(1, Leg.LEFT, 35.25, 0.8725),
        Command(65535, Kind.HEARTBEAT),
        Ack(9, 8, Result.REJECTED_LIMITS),
        Telemetry(3, RobotState.ARMED, (30.0, -2.5), (0.9, 1.0), 7400, 0b101),
    ],
)
def test_round_trip(message):
    assert decode(encode(message)) == message


def test_sequence_numbers_wrap():
    assert decode(encode(Command(65536 + 5, Kind.ARM))).seq == 5


@pytest.mark.parametrize(
    ("payload", "reason"),
    [
        (b"", "shorter"),
        (bytes.fromhex("02 06 0001"), "version"),
        (bytes.fromhex("01 7f 0001"), "unknown message type"),
        (bytes.fromhex("01 01 0001 00 0bb8"), "expected 5"),
        (bytes.fromhex("01 01 0001 05 0bb8 2328"), "SET_LEG"),
        (bytes.fromhex("01 04 0001 00"), "no body"),
    ],
)
def test_malformed_payloads_are_refused(payload, reason):
    with pytest.raises(ProtocolError, match=reason):
        decode(payload)


@given(st.binary(max_size=40))
@settings(max_examples=500, deadline=None)
def test_decoder_never_fails_otherwise(payload):
    try:
        message = decode(payload)
    except ProtocolError:
        return
    assert encode(message) == payload, "a payload that decodes re-encodes to the same bytes"


def test_unencodable_values_are_refused():
    with pytest.raises(ValueError, match="angle"):
        encode(SetLeg(1, Leg.LEFT, 400.0, 0.9))
    with pytest.raises(ValueError, match="leg length"):
        encode(SetLeg(1, Leg.LEFT, 30.0, -0.1))


@pytest.mark.parametrize("wall", list(Wall))
def test_legs_convert_to_and_from_walls(wall):
    leg = Leg.of(wall)
    assert leg.wall is wall
    assert int(leg) == (0 if wall is Wall.LEFT else 1), "the wire values stay 0 (left), 1 (right)"


def test_fault_bits_are_distinct_and_booted_is_bit_5():
    assert Fault.BOOTED == 1 << 5 and Fault.BROWNOUT == 1 << 3
    bits = [int(fault) for fault in Fault]
    assert all(bit & (bit - 1) == 0 for bit in bits) and len(set(bits)) == len(bits), "one bit each"
    booted = Telemetry(2, RobotState.DISARMED, (30.0, 30.0), (0.9, 0.9), 7400, Fault.BOOTED | Fault.BROWNOUT)
    assert encode(booted)[-2:] == bytes.fromhex("0028") and decode(encode(booted)) == booted
