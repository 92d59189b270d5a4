"""A tracker source's frame counts: received, dropped, malformed, ignored and restarts of the numbering.

Shared by every source (PKT1 datagrams, NatNet frames): :class:`TrackerStats` is updated by the
source's receiving thread; :meth:`TrackerStats.snapshot` gives an immutable :class:`TrackerCounts`,
and :meth:`TrackerCounts.since` one run's figures (docs/protocol.md §4.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

FRAME_JUMP = 1000  # frames: ~3 s at 360 Hz, 10 s at 100 Hz; a longer forward gap is a jump, not loss
LATE_FRAMES = 16  # frames: a number this far behind the newest is a late (reordered) datagram, not a restart


@dataclass(frozen=True)
class TrackerCounts:
    """Tracker figures at one moment, or over a stretch (:meth:`since`): frames ``received``,
    ``dropped`` (gaps in the frame numbers), ``malformed`` packets, well-formed frames ``ignored``
    (no pose in them), and ``restarts`` of the numbering (it went back, or jumped ahead further than
    :data:`FRAME_JUMP`)."""

    received: int = 0
    dropped: int = 0
    malformed: int = 0
    ignored: int = 0
    restarts: int = 0

    @property
    def loss(self) -> float:
        """Fraction of frames lost (dropped / expected)."""
        expected = self.received + self.dropped
        return self.dropped / expected if expected else 0.0

    def since(self, earlier: TrackerCounts) -> TrackerCounts:
        """The counts from ``earlier`` (a snapshot of the same stats) to these, e.g. over one run."""
        return TrackerCounts(*(getattr(self, f.name) - getattr(earlier, f.name) for f in fields(self)))


@dataclass
class TrackerStats:
    """A source's running counts (see :class:`TrackerCounts`), updated by its receiving thread.

    Frame numbers: a gap of up to :data:`FRAME_JUMP` counts as dropped frames. A longer jump ahead,
    or a number more than :data:`LATE_FRAMES` behind the newest (the camera software restarted, or
    its 32-bit numbers wrapped), counts as a restart: the new numbering is followed from there, and
    the frames between are not counted lost. A number just behind the newest is a late datagram.

    A malformed packet (its source adds one to ``malformed``; nothing in it is read, not even its frame
    number) is counted once: each malformed since the last frame stands for one of the numbers missing
    before the next frame, which are not counted dropped too. So ``dropped`` holds only the gaps that no
    packet came for (a malformed packet that was no frame at all may hide one of those)."""

    received: int = 0
    dropped: int = 0  # frame-number gaps that no packet, well-formed or malformed, came for
    malformed: int = 0
    ignored: int = 0  # well-formed frames without a pose (NatNet: the rigid body not in it, or not tracked)
    restarts: int = 0  # the numbering went back, or jumped ahead by more than FRAME_JUMP
    last_frame: int | None = None
    _malformed_seen: int = field(default=0, repr=False)  # ``malformed`` as the last frame found it
    _unplaced: int = field(default=0, repr=False)  # malformed since the numbering last moved on

    def frame(self, number: int) -> None:
        """Count a frame received, and the frames lost before it (late ones are not counted twice, nor
        those the malformed packets since the last frame stood for)."""
        self._unplaced += self.malformed - self._malformed_seen
        self._malformed_seen = self.malformed
        last = self.last_frame
        if last is None:
            self.last_frame = number
        elif number > last:
            if number - last - 1 > FRAME_JUMP:
                self.restarts += 1
            else:
                self.dropped += max(0, number - last - 1 - self._unplaced)
            self.last_frame = number
        elif number < last - LATE_FRAMES:
            self.restarts += 1
            self.last_frame = number
        else:  # a late frame: the malformed may yet stand for numbers after the newest
            self.received += 1
            return
        self._unplaced = 0
        self.received += 1

    @property
    def loss(self) -> float:
        """Fraction of frames lost (dropped / expected)."""
        return self.snapshot().loss

    def snapshot(self) -> TrackerCounts:
        """The counts now. Cheap; read while the receiving thread counts, so one field may be a frame
        ahead of another, never more."""
        return TrackerCounts(self.received, self.dropped, self.malformed, self.ignored, self.restarts)
