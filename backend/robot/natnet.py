"""NatNet, the camera software's stream (OptiTrack Motive, NaturalPoint Tracking Tools): its messages.

The lab's FLEX V100 rig runs old Tracking Tools/Motive, so NatNet 2.x matters as much as 3.x and
4.x. This module holds what every NatNet message shares and the client's conversation with the
server: the header, the versions known (frames of 2.0 to 4.1 are read; a later 4.x with 4.1's
layout), a bounded :class:`Reader` that names what a short packet lacked, the client's requests
(connect, keep-alive) and the server's answer to a connect (message 1, ``NAT_SERVERINFO``, which
names the stream's NatNet version). A frame of data (message 7, ``NAT_FRAMEOFDATA``), version by
version, is :mod:`backend.robot.natnet_frame`'s.

Why not the ``natnet`` package (PyPI 0.3.0, read before deciding): its version comparison takes
``Version(2)`` as equal to ``Version(2, 6)`` (it zips the unpadded parts), so a configured
"2" reads 2.6 fields that are not there; it unpacks with native sizes and byte order (``"L"`` is
4 bytes on Windows, the stream is little-endian u64 there); it drops every frame until the server
has answered a connect (a configured version cannot be used); it reads no 4.x precision timestamp,
so the suffix's parameters come from the wrong bytes; it ignores 4.1's block sizes instead of
checking them; and a malformed packet escapes as ``struct.error``/``UnicodeDecodeError`` from a
background thread. What a pose needs is a few hundred lines, checked byte by byte (here and in
:mod:`backend.robot.natnet_frame`).

Layout (little-endian throughout; from the NatNet SDK's PacketClient.cpp and NatNetClient.py).
A message is ``u16 id, u16 byte count`` then that many bytes. Anything malformed raises
:class:`NatNetError`.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from sim_core.model.errors import ParameterError

NAT_CONNECT = 0
NAT_SERVERINFO = 1
NAT_FRAMEOFDATA = 7
NAT_KEEPALIVE = 10
COMMAND_PORT = 1510  # the server's, for requests
DATA_PORT = 1511  # where a multicast stream goes
MULTICAST_GROUP = "239.255.42.99"
OLDEST, NEWEST = (2, 0), (4, 1)  # the frame layouts known; a later 4.x is read as 4.1

Version = tuple[int, int]  # (major, minor)

HEADER = struct.Struct("<HH")  # message id, byte count of what follows
U16, U32, F32, F64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<f"), struct.Struct("<d")
_SERVER_INFO = struct.Struct("<256s4B4B")  # application name, its version, the NatNet version


class NatNetError(ValueError):
    """A packet that is not a well-formed NatNet message for the version it is read with."""


def is_known(version: Version) -> bool:
    """Whether frames of NatNet ``version`` can be read: 2.0 to 4.x (a 4.x after 4.1 as 4.1)."""
    return OLDEST <= version < (NEWEST[0] + 1, 0)


def format_version(version: Version) -> str:
    """``(major, minor)`` as ``"M.m"``."""
    return f"{version[0]}.{version[1]}"


KNOWN_VERSIONS = f"{format_version(OLDEST)} to {NEWEST[0]}.x"  # for messages


def parse_version(text: str, field: str = "natnet_version") -> Version:
    """``"M.m"`` (e.g. ``"2.9"``, ``"4.1"``) as ``(major, minor)``, within the layouts known."""
    major, dot, minor = text.strip().partition(".")
    if not (dot and major.isdigit() and minor.isdigit()):
        raise ParameterError(field, f"must be MAJOR.MINOR such as 2.9 or 4.1, got {text!r}")
    version = (int(major), int(minor))
    if not is_known(version):
        raise ParameterError(field, f"must be from {KNOWN_VERSIONS}, got {text!r}")
    return version


@dataclass(frozen=True)
class ServerInfo:
    application: str
    application_version: tuple[int, int, int, int]
    natnet_version: tuple[int, int, int, int]


class Reader:
    """Reads a message's bytes in order; every read past its end is a :class:`NatNetError` naming what."""

    def __init__(self, data: bytes, offset: int = 0):
        self.data, self.offset = memoryview(data), offset

    @property
    def left(self) -> int:
        return len(self.data) - self.offset

    def take(self, layout: struct.Struct, what: str) -> tuple:
        if layout.size > self.left:
            raise NatNetError(f"truncated at byte {self.offset}: {what} needs {layout.size}, {self.left} left")
        values = layout.unpack_from(self.data, self.offset)
        self.offset += layout.size
        return values

    def u32(self, what: str) -> int:
        return self.take(U32, what)[0]

    def skip(self, size: int, what: str) -> None:
        if size > self.left:
            raise NatNetError(f"truncated at byte {self.offset}: {what} needs {size}, {self.left} left")
        self.offset += size

    def count(self, what: str, smallest: int) -> int:
        """An element count; each element takes at least ``smallest`` bytes, so a count that could not
        fit in the bytes left is refused before anything loops over it."""
        n = self.u32(f"{what} count")
        if n * smallest > self.left:
            raise NatNetError(f"{what} count {n} cannot fit in the {self.left} bytes left")
        return n

    def name(self, what: str) -> None:
        end = bytes(self.data[self.offset :]).find(b"\0")
        if end < 0:
            raise NatNetError(f"truncated at byte {self.offset}: {what} has no terminating zero")
        self.offset += end + 1


def message_id(data: bytes) -> int:
    if len(data) < HEADER.size:
        raise NatNetError(f"a NatNet message has a 4-byte header, got {len(data)} bytes")
    return HEADER.unpack_from(data)[0]


def payload(data: bytes, expected_id: int) -> Reader:
    """A reader at the start of message ``data``'s payload, once its header says ``expected_id``
    and exactly the bytes that follow."""
    ident = message_id(data)
    size = HEADER.unpack_from(data)[1]
    if ident != expected_id:
        raise NatNetError(f"message id {ident}, expected {expected_id}")
    if HEADER.size + size != len(data):
        raise NatNetError(f"the header says {size} bytes follow, the packet has {len(data) - HEADER.size}")
    return Reader(data, HEADER.size)


def decode_server_info(data: bytes) -> ServerInfo:
    """A ``NAT_SERVERINFO`` message (the answer to a connect); 4.x servers append connection
    details, which are not needed here."""
    reader = Reader(data)
    ident, size = reader.take(HEADER, "header")
    if ident != NAT_SERVERINFO or HEADER.size + size != len(data):
        raise NatNetError(f"not a server info message (id {ident}, {size} of {len(data) - 4} bytes)")
    name, *numbers = reader.take(_SERVER_INFO, "server info")
    application = bytes(name).partition(b"\0")[0].decode("utf-8", "replace")
    return ServerInfo(application, tuple(numbers[:4]), tuple(numbers[4:]))


def connect_request(version: Version | None = None) -> bytes:
    """``NAT_CONNECT``: "Ping", then at bytes 265–268 the NatNet version asked for (zeros: the
    server's own; a 4.x server in unicast may switch its bitstream to it), then a zero."""
    request = bytearray(270)
    request[:4] = b"Ping"
    if version is not None:
        request[265:267] = bytes(version)
    request += b"\0"
    return HEADER.pack(NAT_CONNECT, len(request)) + request


def keep_alive() -> bytes:
    """``NAT_KEEPALIVE``: a unicast client sends it so the server keeps streaming to it."""
    return HEADER.pack(NAT_KEEPALIVE, 0) + b"\0"
