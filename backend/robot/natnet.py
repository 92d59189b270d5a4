"""NatNet, the camera software's stream (OptiTrack Motive, NaturalPoint Tracking Tools): its wire format.

The lab's FLEX V100 rig runs old Tracking Tools/Motive, so NatNet 2.x matters as much as 3.x and
4.x. This module reads a frame of data (message 7, ``NAT_FRAMEOFDATA``) for any NatNet version from
2.0 to 4.1 (later 4.x read with 4.1's layout; nothing in 4.2+ changed the frame of data in the
SDK's sample) and keeps what a pose needs: the frame number, the rigid bodies and the timestamp.
It also writes the client's requests (connect, keep-alive) and reads the server's answer to a
connect (message 1, ``NAT_SERVERINFO``, which names the stream's NatNet version). The virtual robot
writes frames with :func:`encode_frame`; the tests check the decoder against an encoder of their own.

Why not the ``natnet`` package (PyPI 0.3.0, read before deciding): its version comparison takes
``Version(2)`` as equal to ``Version(2, 6)`` (it zips the unpadded parts), so a configured
"2" reads 2.6 fields that are not there; it unpacks with native sizes and byte order (``"L"`` is
4 bytes on Windows, the stream is little-endian u64 there); it drops every frame until the server
has answered a connect (a configured version cannot be used); it reads no 4.x precision timestamp,
so the suffix's parameters come from the wrong bytes; it ignores 4.1's block sizes instead of
checking them; and a malformed packet escapes as ``struct.error``/``UnicodeDecodeError`` from a
background thread. What a pose needs is a few hundred lines, checked byte by byte below.

Layout (little-endian throughout; from the NatNet SDK's PacketClient.cpp and NatNetClient.py).
A message is ``u16 id, u16 byte count`` then that many bytes. A frame of data is

- ``u32`` frame number;
- marker sets: count, then each ``name\\0, u32 n, n × 3 f32``;
- unlabeled ("other") markers: count, then ``count × 3 f32``;
- rigid bodies: count, then each ``u32 id, 3 f32 position, 4 f32 quaternion (qx, qy, qz, qw)``,
  before 3.0 ``u32 n, n × 3 f32`` marker positions (and from 2.0 ``n × u32`` ids, ``n × f32``
  sizes), from 2.0 ``f32`` mean marker error, from 2.6 ``u16`` parameters (bit 0: tracking valid);
- skeletons (2.1+): count, then each ``u32 id, u32 n``, ``n`` rigid bodies as above;
- assets (4.1+): count, then each ``u32 id, u32 n``, ``n × 38`` bytes of rigid bodies, ``u32 m``,
  ``m × 26`` bytes of markers;
- labeled markers (2.3+): count, then each ``u32 id, 3 f32, f32 size``, from 2.6 ``u16`` parameters,
  from 3.0 ``f32`` residual;
- force plates (2.9+) and devices (2.11+): count, then each ``u32 id, u32 channels``, each channel
  ``u32 n, n × f32``;
- suffix: before 3.0 ``f32`` software latency [ms], then ``u32`` timecode, ``u32`` sub-timecode,
  timestamp [s] (``f32``, ``f64`` from 2.7), from 3.0 three ``u64`` high-resolution stamps, from 4.1
  the ``u32, u32`` precision timestamp (the SDK's samples disagree whether 4.0 has it: both are
  accepted there), ``u16`` parameters;
- then, optionally, the ``u32`` end-of-data tag that PacketClient.cpp reads after the parameters
  (the SDK never checks its value; NatNetClient.py stops before it, so a frame without it is
  accepted as well).

The software latency is read from 2.x streams as the 2.x and 3.x SDKs' samples (PacketClient.cpp,
NatNetClient.py: "removed in version 3.0") and field readers of real 2.x servers do; the 4.x
samples no longer read it because they no longer talk to such servers.

From 4.1 each block's count is followed by a ``u32`` byte size of the block's elements; it is
checked against what was read. A frame must fill its message exactly, but for the end-of-data tag;
anything else (truncated, oversized, a count that cannot fit, a non-finite timestamp) raises
:class:`NatNetError`.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

from sim_core.errors import ParameterError

NAT_CONNECT = 0
NAT_SERVERINFO = 1
NAT_FRAMEOFDATA = 7
NAT_KEEPALIVE = 10
COMMAND_PORT = 1510  # the server's, for requests
DATA_PORT = 1511  # where a multicast stream goes
MULTICAST_GROUP = "239.255.42.99"
OLDEST, NEWEST = (2, 0), (4, 1)  # the frame layouts known; a later 4.x is read as 4.1
END_TAG_SIZE = 4  # [bytes] the optional end-of-data tag after a frame's parameters

Version = tuple[int, int]  # (major, minor)

_HEADER = struct.Struct("<HH")
_U16, _U32, _F32, _F64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<f"), struct.Struct("<d")
_POSE = struct.Struct("<I3f4f")  # id, position, quaternion (x, y, z, w)
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
class RigidBody:
    """One rigid body as the camera software streams it: ``position`` [camera units, Motive: m],
    ``orientation`` the unit quaternion ``(qx, qy, qz, qw)``, ``mean_error`` [camera units] (NaN
    before 2.0), ``tracked`` the tracking-valid flag (always True before 2.6, which has none)."""

    id: int
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    mean_error: float = math.nan
    tracked: bool = True

    @property
    def angle_about_z(self) -> float:
        """The rotation about the stream's z axis [rad, counter-clockwise seen from +z], in (-π, π]:
        the body's pitch when the air table's plane is the stream's x–y plane."""
        qx, qy, qz, qw = self.orientation
        return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


@dataclass(frozen=True)
class Frame:
    number: int
    timestamp: float  # [s] the camera software's clock
    rigid_bodies: tuple[RigidBody, ...]

    def rigid_body(self, body_id: int) -> RigidBody | None:
        return next((body for body in self.rigid_bodies if body.id == body_id), None)


@dataclass(frozen=True)
class ServerInfo:
    application: str
    application_version: tuple[int, int, int, int]
    natnet_version: tuple[int, int, int, int]


class _Reader:
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
        return self.take(_U32, what)[0]

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
    if len(data) < _HEADER.size:
        raise NatNetError(f"a NatNet message has a 4-byte header, got {len(data)} bytes")
    return _HEADER.unpack_from(data)[0]


def _payload(data: bytes, expected_id: int) -> _Reader:
    ident = message_id(data)
    size = _HEADER.unpack_from(data)[1]
    if ident != expected_id:
        raise NatNetError(f"message id {ident}, expected {expected_id}")
    if _HEADER.size + size != len(data):
        raise NatNetError(f"the header says {size} bytes follow, the packet has {len(data) - _HEADER.size}")
    return _Reader(data, _HEADER.size)


def decode_frame(data: bytes, version: Version) -> Frame:
    """A ``NAT_FRAMEOFDATA`` message, read with the stream's NatNet ``version``."""
    reader = _payload(data, NAT_FRAMEOFDATA)
    sized = version >= (4, 1)
    number = reader.u32("frame number")
    _block(reader, "marker set", sized, 5, lambda: _marker_set(reader))
    _block(reader, "unlabeled marker", sized, 12, lambda: reader.skip(12, "unlabeled marker"))
    rigid_bodies = _block(reader, "rigid body", sized, _POSE.size, lambda: _rigid_body(reader, version))
    if version >= (2, 1):
        _block(reader, "skeleton", sized, 8, lambda: _skeleton(reader, version))
    if version >= (4, 1):
        _block(reader, "asset", sized, 12, lambda: _asset(reader))
    if version >= (2, 3):
        _block(reader, "labeled marker", sized, 20, lambda: _labeled_marker(reader, version))
    if version >= (2, 9):
        _block(reader, "force plate", sized, 8, lambda: _channels(reader, "force plate"))
    if version >= (2, 11):
        _block(reader, "device", sized, 8, lambda: _channels(reader, "device"))
    timestamp = _suffix(reader, version)
    return Frame(number, timestamp, tuple(rigid_bodies))


def _block(reader: _Reader, what: str, sized: bool, smallest: int, element) -> list:
    n = reader.u32(f"{what} count")
    size = reader.u32(f"{what} block size") if sized else None
    if n * smallest > reader.left:
        raise NatNetError(f"{what} count {n} cannot fit in the {reader.left} bytes left")
    start = reader.offset
    elements = [element() for _ in range(n)]
    if size is not None and reader.offset - start != size:
        raise NatNetError(f"the {what} block says {size} bytes, its {n} elements take {reader.offset - start}")
    return elements


def _marker_set(reader: _Reader) -> None:
    reader.name("marker set name")
    reader.skip(12 * reader.count("marker set marker", 12), "marker set markers")


def _rigid_body(reader: _Reader, version: Version) -> RigidBody:
    body_id, x, y, z, qx, qy, qz, qw = reader.take(_POSE, "rigid body pose")
    if version < (3, 0):
        markers = reader.count("rigid body marker", 20 if version >= (2, 0) else 12)
        reader.skip(markers * (20 if version >= (2, 0) else 12), "rigid body markers")
    mean_error = reader.take(_F32, "rigid body mean error")[0] if version >= (2, 0) else math.nan
    tracked = bool(reader.take(_U16, "rigid body parameters")[0] & 1) if version >= (2, 6) else True
    return RigidBody(body_id, (x, y, z), (qx, qy, qz, qw), mean_error, tracked)


def _skeleton(reader: _Reader, version: Version) -> None:
    reader.u32("skeleton id")
    for _ in range(reader.count("skeleton rigid body", _POSE.size)):
        _rigid_body(reader, version)


def _asset(reader: _Reader) -> None:
    reader.u32("asset id")
    reader.skip(38 * reader.count("asset rigid body", 38), "asset rigid bodies")
    reader.skip(26 * reader.count("asset marker", 26), "asset markers")


def _labeled_marker(reader: _Reader, version: Version) -> None:
    size = 20 + (2 if version >= (2, 6) else 0) + (4 if version >= (3, 0) else 0)
    reader.skip(size, "labeled marker")


def _channels(reader: _Reader, what: str) -> None:
    reader.u32(f"{what} id")
    for _ in range(reader.count(f"{what} channel", 4)):
        reader.skip(4 * reader.count(f"{what} channel sample", 4), f"{what} channel samples")


def _suffix(reader: _Reader, version: Version) -> float:
    if version < (3, 0):
        reader.skip(4, "software latency")
    reader.skip(8, "timecode")
    timestamp = reader.take(_F64 if version >= (2, 7) else _F32, "timestamp")[0]
    if version >= (3, 0):
        reader.skip(24, "high-resolution timestamps")
    # 4.0: the precision timestamp is there when 8 bytes more than the parameters (and tag) are left.
    if version >= (4, 1) or (version >= (4, 0) and reader.left in (10, 10 + END_TAG_SIZE)):
        reader.skip(8, "precision timestamp")
    reader.skip(2, "frame parameters")
    if reader.left not in (0, END_TAG_SIZE):
        raise NatNetError(
            f"{reader.left} bytes after the frame's suffix (a NatNet {format_version(version)} frame?); "
            f"only a {END_TAG_SIZE}-byte end-of-data tag may follow"
        )
    if not math.isfinite(timestamp):
        raise NatNetError(f"timestamp {timestamp} is not finite")
    return timestamp


def decode_server_info(data: bytes) -> ServerInfo:
    """A ``NAT_SERVERINFO`` message (the answer to a connect); 4.x servers append connection
    details, which are not needed here."""
    reader = _Reader(data)
    ident, size = reader.take(_HEADER, "header")
    if ident != NAT_SERVERINFO or _HEADER.size + size != len(data):
        raise NatNetError(f"not a server info message (id {ident}, {size} of {len(data) - 4} bytes)")
    name, *numbers = reader.take(_SERVER_INFO, "server info")
    application = bytes(name).partition(b"\0")[0].decode("utf-8", "replace")
    return ServerInfo(application, tuple(numbers[:4]), tuple(numbers[4:]))


def connect_request(version: Version | None = None) -> bytes:
    """``NAT_CONNECT``: "Ping", then at bytes 265–268 the NatNet version asked for (zeros: the
    server's own; a 4.x server in unicast may switch its bitstream to it), then a zero."""
    payload = bytearray(270)
    payload[:4] = b"Ping"
    if version is not None:
        payload[265:267] = bytes(version)
    payload += b"\0"
    return _HEADER.pack(NAT_CONNECT, len(payload)) + payload


def keep_alive() -> bytes:
    """``NAT_KEEPALIVE``: a unicast client sends it so the server keeps streaming to it."""
    return _HEADER.pack(NAT_KEEPALIVE, 0) + b"\0"


def encode_frame(number: int, timestamp: float, body: RigidBody, version: Version) -> bytes:
    """A frame of data holding one rigid body and nothing else, as a server of ``version`` sends it
    (the virtual robot's camera): zero latency and timecode, and a zero end-of-data tag."""
    sized = version >= (4, 1)

    def block(count: int, elements: bytes) -> bytes:
        return _U32.pack(count) + (_U32.pack(len(elements)) if sized else b"") + elements

    rigid = _POSE.pack(body.id, *body.position, *body.orientation)
    if version < (3, 0):
        rigid += _U32.pack(0)  # no per-body markers
    if version >= (2, 0):
        rigid += _F32.pack(0.0 if math.isnan(body.mean_error) else body.mean_error)
    if version >= (2, 6):
        rigid += _U16.pack(1 if body.tracked else 0)
    empty_blocks = 2 + (version >= (2, 1)) + (version >= (4, 1)) + (version >= (2, 3))
    empty_blocks += (version >= (2, 9)) + (version >= (2, 11))
    out = _U32.pack(number & 0xFFFFFFFF) + block(0, b"") * 2 + block(1, rigid) + block(0, b"") * (empty_blocks - 2)
    if version < (3, 0):
        out += _F32.pack(0.0)  # software latency
    out += _U32.pack(0) * 2 + (_F64 if version >= (2, 7) else _F32).pack(timestamp)
    if version >= (3, 0):
        out += bytes(24)
    if version >= (4, 1):
        out += bytes(8)
    out += _U16.pack(0) + _U32.pack(0)  # parameters, end-of-data tag
    return _HEADER.pack(NAT_FRAMEOFDATA, len(out)) + out


def quaternion_about_z(angle: float) -> tuple[float, float, float, float]:
    """The unit quaternion ``(qx, qy, qz, qw)`` of a rotation by ``angle`` [rad] about z (NaN: none known, identity)."""
    if math.isnan(angle):
        return (0.0, 0.0, 0.0, 1.0)
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))
