"""A NatNet frame of data (message 7, ``NAT_FRAMEOFDATA``), version by version: read, and written.

:func:`decode_frame` reads a frame of any NatNet version from 2.0 to 4.1 (later 4.x read with 4.1's
layout; nothing in 4.2+ changed the frame of data in the SDK's sample) and keeps what a pose needs:
the frame number, the rigid bodies and the timestamp. The virtual robot writes frames with
:func:`encode_frame`; the tests check the decoder against an encoder of their own. What every
message shares (the header, versions, :class:`~backend.robot.natnet.NatNetError`) is
:mod:`backend.robot.natnet`'s.

Layout (little-endian throughout; from the NatNet SDK's PacketClient.cpp and NatNetClient.py).
After the message's header (``u16 id, u16 byte count``) a frame of data is

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
- suffix: before 3.0 ``f32`` software latency [ms] (optional, below), then ``u32`` timecode, ``u32``
  sub-timecode, timestamp [s] (``f32``, ``f64`` from 2.7), from 3.0 three ``u64`` high-resolution
  stamps, from 4.1 the ``u32, u32`` precision timestamp (the SDK's samples disagree whether 4.0 has
  it: both are accepted there), ``u16`` parameters;
- then, optionally, the ``u32`` end-of-data tag that PacketClient.cpp reads after the parameters
  (the SDK never checks its value; NatNetClient.py stops before it, so a frame without it is
  accepted as well).

The 2.x software latency: the 2.x SDK's samples (PacketClient.cpp, NatNetClient.py 2.10), the 3.x
PacketClient.cpp ("removed in version 3.0") and field readers of real 2.x servers read it; the 3.x
and 4.x NatNetClient.py, a later PacketClient.cpp and the ``natnet`` package do not, so a sender
written from them leaves it out. Both are read, each with or without the tag: the suffix's size
tells them apart, but for a latency without a tag and a tag without a latency (the same 4 bytes
more). There the SDK's layout (the latency) is taken unless its timestamp is not plausible (outside
:data:`PLAUSIBLE`: read 4 bytes off, it is a subnormal, NaN or absurd number) and the other
reading's is (or is zero). A 2.x suffix just the size of one without both is accepted only with
such a timestamp, which keeps refusing a frame cut 4 bytes short.

From 4.1 each block's count is followed by a ``u32`` byte size of the block's elements; it is
checked against what was read. A frame must fill its message exactly, but for the end-of-data tag
(and a 2.x frame's latency); anything else (truncated, oversized, a count that cannot fit, a
non-finite timestamp) raises :class:`~backend.robot.natnet.NatNetError`.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

from backend.robot.natnet import (
    F32,
    F64,
    HEADER,
    NAT_FRAMEOFDATA,
    U16,
    U32,
    NatNetError,
    Reader,
    Version,
    format_version,
    payload,
)

END_TAG_SIZE = 4  # [bytes] the optional end-of-data tag after a frame's parameters
PLAUSIBLE = (2.0**-20, 2.0**40)  # [s] a timestamp that tells a 2.x frame's latency from its tag (_has_latency)
_POSE = struct.Struct("<I3f4f")  # id, position, quaternion (x, y, z, w)


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


def decode_frame(data: bytes, version: Version) -> Frame:
    """A ``NAT_FRAMEOFDATA`` message, read with the stream's NatNet ``version``."""
    reader = payload(data, NAT_FRAMEOFDATA)
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


def _block(reader: Reader, what: str, sized: bool, smallest: int, element) -> list:
    n = reader.u32(f"{what} count")
    size = reader.u32(f"{what} block size") if sized else None
    if n * smallest > reader.left:
        raise NatNetError(f"{what} count {n} cannot fit in the {reader.left} bytes left")
    start = reader.offset
    elements = [element() for _ in range(n)]
    if size is not None and reader.offset - start != size:
        raise NatNetError(f"the {what} block says {size} bytes, its {n} elements take {reader.offset - start}")
    return elements


def _marker_set(reader: Reader) -> None:
    reader.name("marker set name")
    reader.skip(12 * reader.count("marker set marker", 12), "marker set markers")


def _rigid_body(reader: Reader, version: Version) -> RigidBody:
    body_id, x, y, z, qx, qy, qz, qw = reader.take(_POSE, "rigid body pose")
    if version < (3, 0):
        markers = reader.count("rigid body marker", 20 if version >= (2, 0) else 12)
        reader.skip(markers * (20 if version >= (2, 0) else 12), "rigid body markers")
    mean_error = reader.take(F32, "rigid body mean error")[0] if version >= (2, 0) else math.nan
    tracked = bool(reader.take(U16, "rigid body parameters")[0] & 1) if version >= (2, 6) else True
    return RigidBody(body_id, (x, y, z), (qx, qy, qz, qw), mean_error, tracked)


def _skeleton(reader: Reader, version: Version) -> None:
    reader.u32("skeleton id")
    for _ in range(reader.count("skeleton rigid body", _POSE.size)):
        _rigid_body(reader, version)


def _asset(reader: Reader) -> None:
    reader.u32("asset id")
    reader.skip(38 * reader.count("asset rigid body", 38), "asset rigid bodies")
    reader.skip(26 * reader.count("asset marker", 26), "asset markers")


def _labeled_marker(reader: Reader, version: Version) -> None:
    size = 20 + (2 if version >= (2, 6) else 0) + (4 if version >= (3, 0) else 0)
    reader.skip(size, "labeled marker")


def _channels(reader: Reader, what: str) -> None:
    reader.u32(f"{what} id")
    for _ in range(reader.count(f"{what} channel", 4)):
        reader.skip(4 * reader.count(f"{what} channel sample", 4), f"{what} channel samples")


def _suffix(reader: Reader, version: Version) -> float:
    if version < (3, 0) and _has_latency(reader, version):
        reader.skip(4, "software latency")
    reader.skip(8, "timecode")
    timestamp = reader.take(F64 if version >= (2, 7) else F32, "timestamp")[0]
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


def _has_latency(reader: Reader, version: Version) -> bool:
    """Whether a 2.x frame's suffix begins with the software latency: told by the bytes left (the
    suffix, with or without the latency, with or without the tag), and where the latency without a
    tag and a tag without the latency take the same bytes, by the timestamp each reading gives: the
    latency's (the SDK's layout) unless its timestamp is not plausible and the other's is."""
    stamp = F64 if version >= (2, 7) else F32
    rest = 8 + stamp.size + 2  # timecode, sub-timecode, timestamp, parameters
    left = reader.left
    if left == rest + 4 + END_TAG_SIZE:
        return True
    if left < rest:
        raise NatNetError(
            f"truncated at byte {reader.offset}: the frame's suffix needs {rest} bytes "
            f"({rest + 4} with the software latency), {left} left"
        )
    if left not in (rest, rest + 4):
        raise NatNetError(
            f"{left} bytes after the frame's blocks (a NatNet {format_version(version)} frame?): its suffix "
            f"takes {rest}, {rest + 4} with the software latency; only a {END_TAG_SIZE}-byte end-of-data tag may follow"
        )
    without = stamp.unpack_from(reader.data, reader.offset + 8)[0]  # the timestamp, were no latency there
    if left == rest + 4:  # the latency and no tag, or the tag and no latency
        with_latency = stamp.unpack_from(reader.data, reader.offset + 12)[0]
        return _plausible(with_latency) or not (without == 0.0 or _plausible(without))
    if without == 0.0 or _plausible(without):
        return False
    raise NatNetError(
        f"the frame's suffix is {rest} bytes, as without the software latency and the end-of-data tag, "
        f"but its timestamp would be {without} (a frame cut short?)"
    )


def _plausible(timestamp: float) -> bool:
    """A camera software's clock [s]: from a microsecond (a stamp read from the wrong bytes is mostly a
    tiny, huge, negative or non-finite number) to 2**40 s; zero is told apart by its callers."""
    return PLAUSIBLE[0] <= timestamp < PLAUSIBLE[1]


def encode_frame(number: int, timestamp: float, body: RigidBody, version: Version) -> bytes:
    """A frame of data holding one rigid body and nothing else, as a server of ``version`` sends it
    (the virtual robot's camera): zero latency and timecode, and a zero end-of-data tag."""
    sized = version >= (4, 1)

    def block(count: int, elements: bytes) -> bytes:
        return U32.pack(count) + (U32.pack(len(elements)) if sized else b"") + elements

    rigid = _POSE.pack(body.id, *body.position, *body.orientation)
    if version < (3, 0):
        rigid += U32.pack(0)  # no per-body markers
    if version >= (2, 0):
        rigid += F32.pack(0.0 if math.isnan(body.mean_error) else body.mean_error)
    if version >= (2, 6):
        rigid += U16.pack(1 if body.tracked else 0)
    empty_blocks = 2 + (version >= (2, 1)) + (version >= (4, 1)) + (version >= (2, 3))
    empty_blocks += (version >= (2, 9)) + (version >= (2, 11))
    out = U32.pack(number & 0xFFFFFFFF) + block(0, b"") * 2 + block(1, rigid) + block(0, b"") * (empty_blocks - 2)
    if version < (3, 0):
        out += F32.pack(0.0)  # software latency
    out += U32.pack(0) * 2 + (F64 if version >= (2, 7) else F32).pack(timestamp)
    if version >= (3, 0):
        out += bytes(24)
    if version >= (4, 1):
        out += bytes(8)
    out += U16.pack(0) + U32.pack(0)  # parameters, end-of-data tag
    return HEADER.pack(NAT_FRAMEOFDATA, len(out)) + out


def quaternion_about_z(angle: float) -> tuple[float, float, float, float]:
    """The unit quaternion ``(qx, qy, qz, qw)`` of a rotation by ``angle`` [rad] about z (NaN: none known, identity)."""
    if math.isnan(angle):
        return (0.0, 0.0, 0.0, 1.0)
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))
