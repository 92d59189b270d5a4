"""XBee API frames in escaped mode (AP=2), per Digi's API-mode documentation.

A frame on the wire is ``0x7E``, a 16-bit big-endian length of the frame data, the frame data,
and a checksum ``0xFF - (sum(frame data) & 0xFF)``. After the start byte, every ``0x7E 0x7D 0x11
0x13`` (length and checksum included) is sent as ``0x7D`` followed by the byte XOR ``0x20``. The
checksum is computed on the unescaped data.

:class:`FrameParser` reads a byte stream of any chunking and yields the frames' data. It
resynchronises on the next ``0x7E`` after garbage, a bad checksum, a frame cut short by a new
start byte, or an impossible length, and counts each kind; it never raises on input.

A Transmit Request with a non-zero frame id is answered by the sending radio itself with a
Transmit Status (0x8B): did the frame reach the destination radio, after how many retries.
:class:`TransmitLog` hands out the frame ids and tallies those answers.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

START = 0x7E
ESCAPE = 0x7D
XON = 0x11
XOFF = 0x13
SPECIAL = frozenset({START, ESCAPE, XON, XOFF})
MAX_FRAME_DATA = 256  # far above our largest message; a longer length is corruption

# The robot radio's 64-bit address (its XBee's SH:SL): the PC link addresses the robot by it, and
# the virtual robot's radio answers from it.
ROBOT_ADDRESS = 0x0013A20040B0B0B0

TX_REQUEST = 0x10  # frame types used by the link
RX_PACKET = 0x90
TX_STATUS = 0x8B
BROADCAST_16 = 0xFFFE  # "address unknown": route by the 64-bit address
TX_STATUS_LENGTH = 7  # type, frame id, 16-bit destination, retry count, delivery, discovery

# Transmit Status delivery codes (Digi's API reference); 0x00 is the only success.
DELIVERED = 0x00
ADDRESS_NOT_FOUND = 0x24  # no radio with the destination's 64-bit address answered
DELIVERY_STATUS = {
    0x00: "success",
    0x01: "MAC ACK failure",
    0x02: "CCA failure",
    0x03: "transmission purged",
    0x04: "physical error",
    0x15: "invalid destination endpoint",
    0x18: "no buffers",
    0x21: "network ACK failure",
    0x22: "not joined to network",
    0x23: "self-addressed",
    0x24: "address not found",
    0x25: "route not found",
    0x26: "broadcast source failed to hear a neighbour relay",
    0x2B: "invalid binding table index",
    0x2C: "resource error",
    0x2D: "attempted broadcast with APS transmission",
    0x2E: "attempted unicast with APS transmission, but EE=0",
    0x32: "resource error: lack of free buffers, timers",
    0x74: "data payload too large",
    0x75: "indirect message unrequested",
}


class FrameError(ValueError):
    """A frame's data is not the frame type it claims (raised by the typed decoders only)."""


def checksum(data: bytes) -> int:
    return 0xFF - (sum(data) & 0xFF)


def escape(data: bytes) -> bytes:
    out = bytearray()
    for byte in data:
        if byte in SPECIAL:
            out += bytes((ESCAPE, byte ^ 0x20))
        else:
            out.append(byte)
    return bytes(out)


def encode_frame(data: bytes) -> bytes:
    """One API frame, escaped, around ``data`` (frame type and payload)."""
    if not 1 <= len(data) <= MAX_FRAME_DATA:
        raise ValueError(f"frame data must be 1 to {MAX_FRAME_DATA} bytes, got {len(data)}")
    return bytes((START,)) + escape(struct.pack(">H", len(data)) + data + bytes((checksum(data),)))


@dataclass
class ParserStats:
    """What the parser saw: good frames and each kind of damage."""

    frames: int = 0
    bad_checksum: int = 0
    truncated: int = 0  # a new start byte arrived before the frame was complete
    bad_length: int = 0
    garbage_bytes: int = 0  # bytes outside any frame


@dataclass
class FrameParser:
    """Incremental decoder: ``feed(chunk)`` returns the data of every complete, valid frame."""

    stats: ParserStats = field(default_factory=ParserStats)
    _body: bytearray = field(default_factory=bytearray)  # unescaped bytes after the start byte
    _in_frame: bool = False
    _escaped: bool = False

    def feed(self, chunk: bytes) -> list[bytes]:
        frames = []
        for byte in chunk:
            if byte == START:
                if self._in_frame and self._body:
                    self.stats.truncated += 1
                self._begin()
                continue
            if not self._in_frame:
                self.stats.garbage_bytes += 1
                continue
            if self._escaped:
                byte ^= 0x20
                self._escaped = False
            elif byte == ESCAPE:
                self._escaped = True
                continue
            self._body.append(byte)
            frame = self._complete()
            if frame is not None:
                frames.append(frame)
        return frames

    def _begin(self) -> None:
        self._body.clear()
        self._in_frame = True
        self._escaped = False

    def _complete(self) -> bytes | None:
        body = self._body
        if len(body) < 2:
            return None
        length = (body[0] << 8) | body[1]
        if not 1 <= length <= MAX_FRAME_DATA:
            self.stats.bad_length += 1
            self._in_frame = False
            return None
        if len(body) < length + 3:
            return None
        data, received = bytes(body[2 : 2 + length]), body[2 + length]
        self._in_frame = False
        if checksum(data) != received:
            self.stats.bad_checksum += 1
            return None
        self.stats.frames += 1
        return data


def tx_request(payload: bytes, *, frame_id: int, destination64: int, destination16: int = BROADCAST_16) -> bytes:
    """Frame data of a Transmit Request (0x10) carrying ``payload`` (no broadcast radius, no options)."""
    return struct.pack(">BBQHBB", TX_REQUEST, frame_id & 0xFF, destination64, destination16, 0, 0) + payload


@dataclass(frozen=True)
class Received:
    """A Receive Packet (0x90)."""

    source64: int
    source16: int
    options: int
    payload: bytes


def parse_rx_packet(data: bytes) -> Received:
    if len(data) < 12 or data[0] != RX_PACKET:
        raise FrameError(f"not a receive packet (0x90): {data[:1].hex() or 'empty'}, {len(data)} bytes")
    _kind, source64, source16, options = struct.unpack(">BQHB", data[:12])
    return Received(source64, source16, options, bytes(data[12:]))


def parse_tx_request(data: bytes) -> tuple[int, int, bytes]:
    """``(frame id, destination64, payload)`` of a Transmit Request — what a robot's radio receives."""
    if len(data) < 14 or data[0] != TX_REQUEST:
        raise FrameError(f"not a transmit request (0x10): {data[:1].hex() or 'empty'}, {len(data)} bytes")
    _kind, frame_id, destination64, _destination16, _radius, _options = struct.unpack(">BBQHBB", data[:14])
    return frame_id, destination64, bytes(data[14:])


def rx_packet(payload: bytes, *, source64: int, source16: int = BROADCAST_16, options: int = 0x01) -> bytes:
    """Frame data of a Receive Packet (0x90), as the PC's radio delivers the robot's messages."""
    return struct.pack(">BQHB", RX_PACKET, source64, source16, options) + payload


@dataclass(frozen=True)
class TransmitStatus:
    """A Transmit Status (0x8B): the local radio's report on the Transmit Request ``frame_id``."""

    frame_id: int
    destination16: int
    retries: int  # transmission retries the radio made (the count it reports)
    delivery: int  # 0x00 delivered; otherwise why not (DELIVERY_STATUS)
    discovery: int  # 0x00 no discovery overhead, 0x01 address, 0x02 route, 0x03 both

    @property
    def delivered(self) -> bool:
        return self.delivery == DELIVERED

    @property
    def delivery_name(self) -> str:
        """``"address not found (0x24)"``: the code's name and the code, unknown codes included."""
        return f"{DELIVERY_STATUS.get(self.delivery, 'unknown')} (0x{self.delivery:02X})"


def parse_tx_status(data: bytes) -> TransmitStatus:
    if len(data) != TX_STATUS_LENGTH or data[0] != TX_STATUS:
        raise FrameError(f"not a transmit status (0x8B): {data[:1].hex() or 'empty'}, {len(data)} bytes")
    _kind, frame_id, destination16, retries, delivery, discovery = struct.unpack(">BBHBBB", data)
    return TransmitStatus(frame_id, destination16, retries, delivery, discovery)


def tx_status(
    frame_id: int, *, delivery: int = DELIVERED, retries: int = 0, discovery: int = 0, destination16: int = BROADCAST_16
) -> bytes:
    """Frame data of a Transmit Status (0x8B), as a radio answers a Transmit Request with ``frame_id``."""
    return struct.pack(">BBHBBB", TX_STATUS, frame_id & 0xFF, destination16, retries, delivery, discovery)


@dataclass
class TransmitLog:
    """Frame ids for the Transmit Requests one sender writes, and the Transmit Statuses heard back.

    Ids cycle 1..255: frame id 0 asks the radio for no Transmit Status. One writer at a time calls
    :meth:`next_frame_id` (the link holds its write lock) and one reader calls :meth:`heard`."""

    statuses: int = 0  # Transmit Statuses heard
    failures: int = 0  # of which not delivered
    retries: int = 0  # the radio's transmission retries, summed over the statuses heard
    last_failure: str | None = None  # the last failure's delivery_name
    _frame_id: int = 0

    def next_frame_id(self) -> int:
        self._frame_id = self._frame_id % 255 + 1
        return self._frame_id

    def heard(self, status: TransmitStatus) -> None:
        self.statuses += 1
        self.retries += status.retries
        if not status.delivered:
            self.failures += 1
            self.last_failure = status.delivery_name
