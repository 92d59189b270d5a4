"""NatNet packets for the tests, written from the published frame layout (the NatNet SDK's
PacketClient.cpp and NatNetClient.py), separately from :mod:`backend.robot.natnet_frame`, so the decoder
is checked against another reading of the layout, not against itself.

Versions are numbers ``100 * major + minor`` here (2.9 is 209, 4.1 is 401). A scene holds something
in every block the version has, so a decoder that misplaces one block misreads everything after it.
The suffix follows PacketClient.cpp: a 2.x frame's software latency before the timecode, and (when
``end_tag`` is given) the 4-byte end-of-data tag after the frame parameters. ``latency=False`` writes a
2.x frame as the SDK's NatNetClient.py 3.x/4.x, its later PacketClient.cpp and the ``natnet`` package
read one: without the software latency (what an independent sender written from them sends).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Body:
    id: int
    position: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]  # qx, qy, qz, qw
    markers: tuple[tuple[float, float, float], ...] = ((0.01, 0.02, 0.0), (-0.01, 0.0, 0.0))
    error: float = 0.0005
    valid: bool = True


VERSIONS = [200, 201, 203, 205, 206, 207, 209, 210, 211, 300, 301, 400, 401]
PITCH = 0.3  # [rad] body 2's rotation about z
BODIES = (  # what the tests' camera sees: a body, a pitched one, an untracked one
    Body(1, (0.1, 0.2, 0.05), (0.0, 0.0, 0.0, 1.0)),
    Body(2, (-0.25, 1.5, 0.02), (0.0, 0.0, math.sin(PITCH / 2), math.cos(PITCH / 2)), error=0.0007),
    Body(3, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), markers=(), valid=False),
)


@dataclass(frozen=True)
class Scene:
    frame: int
    timestamp: float
    bodies: tuple[Body, ...]
    marker_sets: tuple[tuple[str, int], ...] = (("climber", 3), ("all", 5))  # name, marker count
    unlabeled: int = 2
    skeletons: tuple[tuple[int, tuple[Body, ...]], ...] = ((4, (Body(40, (1.0, 2.0, 3.0), (0, 0, 0, 1)),)),)
    assets: tuple[tuple[int, int, int], ...] = ((9, 2, 3),)  # id, rigid bodies, markers
    labeled: int = 3
    force_plates: tuple[tuple[int, tuple[int, ...]], ...] = ((1, (3, 0, 2)),)  # id, samples per channel
    devices: tuple[tuple[int, tuple[int, ...]], ...] = ((2, (1,)), (3, ()))
    extra: dict = field(default_factory=dict)


def _body(body: Body, v: int) -> bytes:
    out = struct.pack("<i", body.id) + struct.pack("<3f", *body.position) + struct.pack("<4f", *body.quaternion)
    if v < 300:
        out += struct.pack("<i", len(body.markers))
        out += b"".join(struct.pack("<fff", *m) for m in body.markers)
        if v >= 200:
            out += b"".join(struct.pack("<i", 100 + k) for k in range(len(body.markers)))
            out += b"".join(struct.pack("<f", 0.012) for _ in body.markers)
    if v >= 200:
        out += struct.pack("<f", body.error)
    if v >= 206:
        out += struct.pack("<h", 1 if body.valid else 0)
    return out


def _section(v: int, count: int, content: bytes) -> bytes:
    """A block: its count, from 4.1 its byte size, its content."""
    return struct.pack("<i", count) + (struct.pack("<i", len(content)) if v >= 401 else b"") + content


def _channels(things, v: int) -> bytes:
    content = b""
    for ident, samples in things:
        content += struct.pack("<ii", ident, len(samples))
        for n in samples:
            content += struct.pack("<i", n) + struct.pack(f"<{n}f", *([0.5] * n))
    return _section(v, len(things), content)


def frame_packet(scene: Scene, v: int, end_tag: int | None = None, *, latency: bool = True) -> bytes:
    """The NAT_FRAMEOFDATA message of ``scene`` as a server of version ``v`` sends it, ending with the
    end-of-data tag ``end_tag`` (a u32) unless it is None; a 2.x frame without its software latency
    when ``latency`` is False."""
    p = struct.pack("<i", scene.frame)
    sets = b"".join(
        name.encode() + b"\0" + struct.pack("<i", n) + struct.pack("<fff", 1, 2, 3) * n for name, n in scene.marker_sets
    )
    p += _section(v, len(scene.marker_sets), sets)
    p += _section(v, scene.unlabeled, struct.pack("<fff", 0.3, 0.2, 0.1) * scene.unlabeled)
    p += _section(v, len(scene.bodies), b"".join(_body(b, v) for b in scene.bodies))
    if v >= 201:
        skeletons = b"".join(
            struct.pack("<ii", i, len(bs)) + b"".join(_body(b, v) for b in bs) for i, bs in scene.skeletons
        )
        p += _section(v, len(scene.skeletons), skeletons)
    if v >= 401:
        assets = b""
        for ident, n_bodies, n_markers in scene.assets:
            assets += struct.pack("<ii", ident, n_bodies)
            assets += (struct.pack("<i3f4f", 7, 0, 0, 0, 0, 0, 0, 1) + struct.pack("<fh", 0.001, 1)) * n_bodies
            assets += (
                struct.pack("<i", n_markers)
                + (struct.pack("<i3ff", 8, 1, 1, 1, 0.01) + struct.pack("<hf", 0, 0.0)) * n_markers
            )
        p += _section(v, len(scene.assets), assets)
    if v >= 203:
        one = struct.pack("<i3ff", 0x00010002, 0.1, 0.2, 0.3, 0.014)
        if v >= 206:
            one += struct.pack("<h", 0x04)
        if v >= 300:
            one += struct.pack("<f", 0.0002)
        p += _section(v, scene.labeled, one * scene.labeled)
    if v >= 209:
        p += _channels(scene.force_plates, v)
    if v >= 211:
        p += _channels(scene.devices, v)
    if v < 300 and latency:
        p += struct.pack("<f", 4.5)  # software latency [ms]
    p += struct.pack("<II", 0x01020304, 5)  # timecode, sub-timecode
    p += struct.pack("<d" if v >= 207 else "<f", scene.timestamp)
    if v >= 300:
        p += struct.pack("<QQQ", 10**9, 10**9 + 5, 10**9 + 9)
    if v >= 401:
        p += struct.pack("<II", 3600, 12345)
    p += struct.pack("<h", 0)
    if end_tag is not None:
        p += struct.pack("<I", end_tag)
    return struct.pack("<hH", 7, len(p)) + p


def server_info_packet(name: str, app_version: tuple[int, ...], natnet_version: tuple[int, ...]) -> bytes:
    """NAT_SERVERINFO as the server answers a connect; a 4.x server adds its connection details."""
    p = name.encode().ljust(256, b"\0") + bytes(app_version) + bytes(natnet_version)
    if natnet_version[0] >= 4:
        p += struct.pack("<QH?4s", 10**7, 1511, True, bytes([239, 255, 42, 99]))
    return struct.pack("<hH", 1, len(p)) + p
