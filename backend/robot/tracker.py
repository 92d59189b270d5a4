"""Tracker input: body poses from the overhead camera, behind one interface.

A pose is ``(time [s], x [m], y [m], pitch [rad] or NaN)`` in wall coordinates — x across the
chute from its centre line, y up — after :class:`Calibration` maps camera coordinates there.

Sources (all ``PoseSource``: ``latest()`` and ``poses_since(t)``):

- :class:`UdpPoseSource` — ParkourLab tracker datagrams (below) on a UDP port: the virtual
  robot's default stream, or any bridge that sends them. Tests use unicast on 127.0.0.1.
- :class:`backend.robot.natnet_source.NatNetPoseSource` — the camera software's own NatNet stream
  (NaturalPoint/OptiTrack: multicast 239.255.42.99 on data port 1511, or unicast), one rigid body
  of it; the virtual robot can stream NatNet too. Chosen at connect (``tracker_protocol``).
- :func:`recorded_poses` — a recorded run (replay).

Tracker datagram v1 (big-endian, 40 bytes): magic ``b"PKT1"``, frame number u32, time f64,
x f64, y f64, pitch f64 (NaN when the markers do not give it). Gaps in frame numbers are
counted as dropped frames, a jump or a restart of the numbering as a restart (:class:`TrackerStats`);
malformed datagrams are counted and ignored. :meth:`TrackerStats.snapshot` and
:meth:`TrackerCounts.since` give the figures of one run.
"""

from __future__ import annotations

import bisect
import math
import select
import socket
import struct
import threading
import time
from dataclasses import dataclass

import numpy as np

from backend.robot.tracker_stats import FRAME_JUMP, LATE_FRAMES, TrackerCounts, TrackerStats  # noqa: F401 (re-exported)
from sim_core.model.validation import check_range

DATAGRAM = struct.Struct(">4sIdddd")
MAGIC = b"PKT1"
STALE_AFTER = 0.1  # [s] a pose older than this is stale (10 frames at 100 Hz)
HISTORY = 60_000  # poses kept in memory (10 minutes at 100 Hz)


@dataclass(frozen=True)
class Pose:
    time: float
    x: float
    y: float
    pitch: float = math.nan


@dataclass(frozen=True)
class Calibration:
    """Camera to wall coordinates: ``wall = scale * (camera - origin)``, rotated by ``angle``.

    ``origin`` is the camera point of the chute's centre line at the floor, ``angle`` [rad] the
    camera's rotation from the walls' direction, ``scale`` [m per camera unit]. Stored with each run.
    """

    origin: tuple[float, float] = (0.0, 0.0)
    angle: float = 0.0
    scale: float = 1.0

    def __post_init__(self) -> None:
        check_range("calibration.scale", self.scale, 0.0)
        check_range("calibration.angle", self.angle, -math.pi, math.pi, low_open=False, high_open=False)

    def to_wall(self, x: float, y: float) -> tuple[float, float]:
        dx, dy = x - self.origin[0], y - self.origin[1]
        cos, sin = math.cos(self.angle), math.sin(self.angle)
        return self.scale * (cos * dx + sin * dy), self.scale * (-sin * dx + cos * dy)


def encode_datagram(frame: int, pose: Pose) -> bytes:
    return DATAGRAM.pack(MAGIC, frame & 0xFFFFFFFF, pose.time, pose.x, pose.y, pose.pitch)


def decode_datagram(data: bytes) -> tuple[int, Pose]:
    if len(data) != DATAGRAM.size:
        raise ValueError(f"tracker datagram of {len(data)} bytes, expected {DATAGRAM.size}")
    magic, frame, t, x, y, pitch = DATAGRAM.unpack(data)
    if magic != MAGIC or not all(math.isfinite(v) for v in (t, x, y)):
        raise ValueError("not a ParkourLab tracker datagram")
    return frame, Pose(t, x, y, pitch)


class PoseHistory:
    """Poses in time order with thread-safe appends and reads. The newest HISTORY are kept; an
    index (:meth:`count`, :meth:`poses_from`) counts every pose received, so it stays valid when
    older ones are let go (a live run holds its own copy of the frames it journals)."""

    def __init__(self, calibration: Calibration, stale_after: float = STALE_AFTER):
        self.calibration = calibration
        self.stale_after = stale_after
        self._poses: list[Pose] = []
        self._times: list[float] = []
        self._arrived = -math.inf  # time.monotonic() of the newest pose's arrival
        self._released = 0  # poses let go from the front: _poses[0] is the pose with this index
        self._lock = threading.Lock()

    def add(self, pose: Pose) -> None:
        x, y = self.calibration.to_wall(pose.x, pose.y)
        with self._lock:
            self._poses.append(Pose(pose.time, x, y, pose.pitch))
            self._times.append(pose.time)
            self._arrived = time.monotonic()
            if len(self._poses) > HISTORY:
                excess = len(self._poses) - HISTORY
                del self._poses[:excess]
                del self._times[:excess]
                self._released += excess

    def latest(self, now: float | None = None) -> Pose | None:
        """The newest pose, or None if there is none or it is stale: it arrived more than
        ``stale_after`` ago (``now`` on the ``time.monotonic()`` clock; the poses' own times are
        the camera's clock, which the PC's need not match)."""
        with self._lock:
            pose, arrived = (self._poses[-1] if self._poses else None), self._arrived
        if pose is None or (time.monotonic() if now is None else now) - arrived > self.stale_after:
            return None
        return pose

    def arrived(self) -> float:
        """When the newest pose arrived (``time.monotonic()``; ``-inf`` before the first): a live
        run's watch on its eyes (:mod:`backend.robot.tracker_watch`)."""
        with self._lock:
            return self._arrived

    def waiting(self) -> bool:
        """Whether datagrams wait unread (a source's receiving thread behind); a recorded history: never."""
        return False

    def count(self) -> int:
        """Poses received so far, all of them (an index for :meth:`poses_from`)."""
        with self._lock:
            return self._released + len(self._poses)

    def poses_from(self, index: int) -> list[Pose]:
        """Poses from the ``index``-th received on, or from the oldest still kept (no copy of the
        older ones)."""
        return self.numbered_from(index)[1]

    def numbered_from(self, index: int) -> tuple[int, list[Pose]]:
        """:meth:`poses_from`, with the index of the first pose returned (``index``, or the oldest
        kept's when older ones were let go)."""
        with self._lock:
            first = max(index, self._released)
            return first, self._poses[first - self._released :]

    def newest_time(self, first: int = 0) -> float | None:
        """The tracker's time [s] of the newest pose, or None while no pose from the ``first``-th
        received on (a :meth:`count` index) has arrived: a live run's stamp on what it records, so
        that its recording places it among its frames on one clock (docs/service.md, "Recordings")."""
        with self._lock:
            if self._released + len(self._poses) <= first:
                return None
            return self._poses[-1].time

    def poses_since(self, since: float) -> list[Pose]:
        with self._lock:
            return self._poses[bisect.bisect_left(self._times, since) :]

    def as_arrays(self) -> dict[str, np.ndarray]:
        with self._lock:
            poses = list(self._poses)
        return pose_arrays(poses)


def pose_arrays(poses: list[Pose]) -> dict[str, np.ndarray]:
    """``time``, ``x``, ``y`` and ``pitch`` of ``poses``, each as an array."""
    return {name: np.array([getattr(p, name) for p in poses]) for name in ("time", "x", "y", "pitch")}


class UdpPoseSource(PoseHistory):
    """Receives tracker datagrams on ``host:port`` in a background thread.

    For records: ``protocol`` ``"pkt1"``, ``version`` ``"1"`` (the datagram's), ``error`` always None
    (a PKT1 stream has nothing to disagree about)."""

    protocol = "pkt1"
    version = "1"
    error: str | None = None

    def __init__(self, host: str = "127.0.0.1", port: int = 0, *, calibration: Calibration | None = None, **kwargs):
        super().__init__(calibration or Calibration(), **kwargs)
        self.stats = TrackerStats()
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.bind((host, port))
        self.socket.settimeout(0.05)
        self.address = self.socket.getsockname()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._receive, name="tracker-udp", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2)
        self.socket.close()

    def waiting(self) -> bool:
        return readable(self.socket)

    def _receive(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.socket.recv(1024)
            except TimeoutError:
                continue
            except OSError:
                return
            try:
                frame, pose = decode_datagram(data)
            except ValueError:
                self.stats.malformed += 1
                continue
            self.stats.frame(frame)
            self.add(pose)


def recorded_poses(columns: dict[str, np.ndarray]) -> PoseHistory:
    """A recorded pose stream (arrays ``time, x, y`` and optionally ``pitch``, wall coordinates), for replay."""
    history = PoseHistory(Calibration())
    pitch = columns.get("pitch", np.full(len(columns["time"]), math.nan))
    for t, x, y, p in zip(columns["time"], columns["x"], columns["y"], pitch, strict=True):
        history.add(Pose(float(t), float(x), float(y), float(p)))
    return history


def readable(*sockets: socket.socket) -> bool:
    """Whether a datagram waits on any of ``sockets`` (False once closed)."""
    try:
        return bool(select.select(sockets, [], [], 0)[0])
    except (OSError, ValueError):
        return False
