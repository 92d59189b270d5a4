"""ParkourLab's application messages, carried in XBee TX/RX payloads (protocol version 1).

Every message starts with a 4-byte header: protocol version (u8), message type (u8), sequence
number (u16, wrapping), then a fixed body for its type; integers are big-endian. Angles travel
in centidegrees (i16), leg lengths in 1/10000 of l0 (u16), so a message never carries a float.

PC → robot:  SET_LEG (a leg's angle and retraction for its next touchdown), ARM, START (armed:
launch and keep jumping), DISARM, ESTOP (latching; sent repeatedly), RESET (clears an e-stop),
HEARTBEAT.
Robot → PC:  ACK (of a command's sequence number, with a result code), TELEMETRY (state, servo
positions, battery, fault flags — BOOTED after a boot, until the first ARM), HEARTBEAT.

:func:`decode` raises :class:`ProtocolError` on anything malformed; the link counts and drops it.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from enum import IntEnum

from sim_core.model.walls import Wall

VERSION = 1
HEADER = struct.Struct(">BBH")


class ProtocolError(ValueError):
    """A payload that is not a valid version-1 message."""


class Kind(IntEnum):
    SET_LEG = 0x01
    ARM = 0x02
    DISARM = 0x03
    ESTOP = 0x04
    RESET = 0x05
    HEARTBEAT = 0x06
    START = 0x07
    ACK = 0x81
    TELEMETRY = 0x82


class Leg(IntEnum):
    """A leg as the wire encodes it (one byte: 0 left, 1 right). Outside the codec, speak
    :class:`sim_core.model.walls.Wall`: ``Leg.of(wall)`` and ``leg.wall`` convert."""

    LEFT = 0
    RIGHT = 1

    @classmethod
    def of(cls, wall: Wall) -> Leg:
        """The leg that stands on ``wall``."""
        return cls.LEFT if Wall(wall) == Wall.LEFT else cls.RIGHT

    @property
    def wall(self) -> Wall:
        """The wall this leg stands on."""
        return Wall.LEFT if self == Leg.LEFT else Wall.RIGHT


class Result(IntEnum):
    """ACK result codes."""

    OK = 0
    REJECTED_LIMITS = 1  # outside the servo limits: not applied
    REJECTED_STATE = 2  # not allowed in the current state (e.g. commands while e-stopped)
    UNKNOWN = 3


class RobotState(IntEnum):
    DISARMED = 0
    ARMED = 1
    RUNNING = 2
    ESTOPPED = 3


class Fault(IntEnum):
    """TELEMETRY fault bits."""

    HEARTBEAT_LOST = 1 << 0
    LOW_BATTERY = 1 << 1
    SERVO_LIMIT = 1 << 2
    BROWNOUT = 1 << 3
    FELL = 1 << 4  # a jump failed (slip, no flight, ...): the robot is down
    BOOTED = 1 << 5  # the firmware started (power-up, brown-out, reset) and no ARM was accepted since


@dataclass(frozen=True)
class SetLeg:
    seq: int
    leg: Leg
    psi0_deg: float
    zeta0: float


@dataclass(frozen=True)
class Command:
    """ARM, DISARM, ESTOP, RESET or HEARTBEAT: a header and nothing else."""

    seq: int
    kind: Kind


@dataclass(frozen=True)
class Ack:
    seq: int
    acked: int
    result: Result


@dataclass(frozen=True)
class Telemetry:
    seq: int
    state: RobotState
    psi_servo_deg: tuple[float, float]  # L, R
    zeta_servo: tuple[float, float]  # L, R
    battery_mv: int
    faults: int


Message = SetLeg | Command | Ack | Telemetry

_SET_LEG = struct.Struct(">BhH")
_ACK = struct.Struct(">HB")
_TELEMETRY = struct.Struct(">BhhHHHH")
_BARE = {Kind.ARM, Kind.DISARM, Kind.ESTOP, Kind.RESET, Kind.HEARTBEAT, Kind.START}


def encode(message: Message) -> bytes:
    seq = message.seq & 0xFFFF
    if isinstance(message, SetLeg):
        body = _SET_LEG.pack(int(message.leg), _centidegrees(message.psi0_deg), _ten_thousandths(message.zeta0))
        return HEADER.pack(VERSION, Kind.SET_LEG, seq) + body
    if isinstance(message, Command):
        if message.kind not in _BARE:
            raise ValueError(f"{message.kind.name} is not a bare command")
        return HEADER.pack(VERSION, message.kind, seq)
    if isinstance(message, Ack):
        return HEADER.pack(VERSION, Kind.ACK, seq) + _ACK.pack(message.acked & 0xFFFF, int(message.result))
    if isinstance(message, Telemetry):
        body = _TELEMETRY.pack(
            int(message.state),
            _centidegrees(message.psi_servo_deg[0]),
            _centidegrees(message.psi_servo_deg[1]),
            _ten_thousandths(message.zeta_servo[0]),
            _ten_thousandths(message.zeta_servo[1]),
            message.battery_mv,
            message.faults,
        )
        return HEADER.pack(VERSION, Kind.TELEMETRY, seq) + body
    raise TypeError(f"not a message: {message!r}")


def decode(payload: bytes) -> Message:
    if len(payload) < HEADER.size:
        raise ProtocolError(f"payload of {len(payload)} bytes is shorter than the {HEADER.size}-byte header")
    version, kind_code, seq = HEADER.unpack_from(payload)
    if version != VERSION:
        raise ProtocolError(f"protocol version {version}, expected {VERSION}")
    try:
        kind = Kind(kind_code)
    except ValueError:
        raise ProtocolError(f"unknown message type 0x{kind_code:02x}") from None
    body = payload[HEADER.size :]
    try:
        if kind == Kind.SET_LEG:
            leg, centideg, zeta = _exact(_SET_LEG, body)
            return SetLeg(seq, Leg(leg), centideg / 100.0, zeta / 10_000.0)
        if kind in _BARE:
            if body:
                raise ProtocolError(f"{kind.name} carries no body, got {len(body)} bytes")
            return Command(seq, kind)
        if kind == Kind.ACK:
            acked, result = _exact(_ACK, body)
            return Ack(seq, acked, Result(result))
        state, psi_l, psi_r, zeta_l, zeta_r, battery, faults = _exact(_TELEMETRY, body)
        return Telemetry(
            seq,
            RobotState(state),
            (psi_l / 100.0, psi_r / 100.0),
            (zeta_l / 10_000.0, zeta_r / 10_000.0),
            battery,
            faults,
        )
    except ValueError as error:  # enum values out of range
        raise ProtocolError(f"{kind.name}: {error}") from None


def _exact(layout: struct.Struct, body: bytes) -> tuple:
    if len(body) != layout.size:
        raise ProtocolError(f"body of {len(body)} bytes, expected {layout.size}")
    return layout.unpack(body)


def on_the_wire(psi0_deg: float, zeta0: float) -> tuple[float, float]:
    """A leg command as SET_LEG carries it (0.01° and 0.0001 l0 steps, rounded): what the robot
    gets, so what the servo limits are checked against. Non-finite values pass through, for the
    check to refuse."""
    if not (math.isfinite(psi0_deg) and math.isfinite(zeta0)):
        return psi0_deg, zeta0
    return round(psi0_deg * 100.0) / 100.0, round(zeta0 * 10_000.0) / 10_000.0


def _centidegrees(degrees: float) -> int:
    value = round(degrees * 100.0)
    if not -32768 <= value <= 32767:
        raise ValueError(f"angle {degrees} deg is outside the encodable ±327.67 deg")
    return value


def _ten_thousandths(fraction: float) -> int:
    value = round(fraction * 10_000.0)
    if not 0 <= value <= 65535:
        raise ValueError(f"leg length {fraction} l0 is outside the encodable 0 to 6.5535")
    return value
