"""A live run's eyes: how long the tracker has gone without a pose of the robot, and why.

A closed loop acts on the touchdowns the tracker shows it. Without poses it would go on sending the
commands of a climb it cannot see (found: an lqr run kept ``running`` 27 s with its touchdowns
frozen until the body fell; a pid run ran blind to its time limit and was stored as done).
:class:`TrackerWatch` is asked on every turn of the run's loop; once no pose has arrived for its
``bound`` it names the gap: the tracker **silent** (no frame at all: the camera, its software or the
network stopped) or streaming **without the body** (NatNet: the rigid body missing from its frames,
or its tracking-valid bit off). A closed loop ends on it at once and disarms; an open loop is not
steered by the tracker and goes on, its gaps recorded (:attr:`TrackerWatch.gaps`).

The bound (:data:`TRACKER_TIMEOUT_MS`, a run may choose within :data:`TRACKER_TIMEOUT_RANGE_MS`):
the FLEX V100 streams at 100 Hz, so 100 ms is ten frame periods — with the 2 % of frames a rig
loses at random, ten in a row lost by chance is a 1e-17 event, so a gap that long is the tracker's
failure, not noise. A jump of the paper's robot lasts about 0.56 s (56 frames), so the run ends
within a fifth of a jump of going blind, before the law has missed a touchdown. Below 30 ms (three
frames) a late datagram would end runs; above 250 ms (half a jump) the law could lose a whole
flight and command the jump after it blind.

Times are on this PC's ``time.monotonic()`` clock, as the source's receiving thread stamped each
pose's arrival: never the camera's own clock. A loaded machine can hold up the receiving thread
while datagrams wait in its socket: that is this PC falling behind, not the tracker falling
silent, so a gap is not named while the source says datagrams are waiting (``waiting``) — up to
twice the bound, past which a receiver that far behind is as blind as a silent camera. (Measured
before this rule at load 7.5 on two cores: 4 of 17 closed loops ended "tracker silent" after
105–109 ms.) A gap is also confirmed on two looks a poll apart, so a run loop that was itself held
up first lets the receiving thread read what waited.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

TRACKER_TIMEOUT_MS = 100.0  # [ms] the default bound: ten frame periods at 100 Hz
TRACKER_TIMEOUT_RANGE_MS = (30.0, 250.0)  # [ms] the bounds a run may choose (three frames to half a jump)


@dataclass(frozen=True)
class TrackerGap:
    """A stretch without a pose of the robot: from ``since`` (``time.monotonic()`` of the last pose,
    or of the watch's start) for ``seconds``; ``body_lost``: frames kept arriving, without the body."""

    since: float
    seconds: float
    body_lost: bool

    def reason(self, bound_s: float) -> str:
        """The run's end reason for a closed loop (``tracker silent: …`` or ``tracker lost the body: …``)."""
        gap, bound = f"{self.seconds * 1000:.0f} ms", f"{bound_s * 1000:.0f} ms"
        if self.body_lost:
            return f"tracker lost the body: frames arrive without it, no pose for {gap} (bound {bound})"
        return f"tracker silent: no frame for {gap} (bound {bound})"

    def to_record(self, monotonic_now: float, unix_now: float) -> dict:
        """As a run stores it: when it began [Unix time, s], how long it lasted [ms], which kind."""
        return {
            "time": unix_now - (monotonic_now - self.since),
            "ms": self.seconds * 1000.0,
            "kind": "body lost" if self.body_lost else "silent",
        }


class TrackerWatch:
    """Watches one run's pose arrivals (the run loop's thread only).

    ``bound_s``: the longest a run may go without a pose [s]; ``now``: the watch's start (the
    robot launched), ``frames``: the source's frames received so far (any, with or without the body).
    """

    def __init__(self, bound_s: float, now: float, frames: int):
        self.bound_s = bound_s
        self.gaps: list[TrackerGap] = []  # gaps past the bound that have ended, oldest first
        self._last_pose = now
        self._frames_at_pose = frames
        self._over = 0  # consecutive looks that found the gap past the bound
        self._open: TrackerGap | None = None  # the gap past the bound now going on

    def look(self, now: float, last_pose: float, frames: int, waiting: bool = False) -> TrackerGap | None:
        """The gap going on, once it is past the bound on two looks in a row; else None.
        ``last_pose``: the newest pose's arrival (``-inf`` if none yet), ``frames``: as in the
        constructor, ``waiting``: datagrams wait unread in the source's socket."""
        if last_pose > self._last_pose:  # a pose since the last look: any gap past the bound has ended
            if self._open is not None:
                self.gaps.append(replace(self._open, seconds=last_pose - self._open.since))
                self._open = None
            self._last_pose, self._frames_at_pose = last_pose, frames
        silent = now - self._last_pose
        if silent <= self.bound_s or (waiting and silent <= 2.0 * self.bound_s):
            self._over = 0
            return None
        self._over += 1
        if self._over < 2:
            return None
        self._open = TrackerGap(self._last_pose, silent, body_lost=frames > self._frames_at_pose)
        return self._open

    def closed(self, now: float) -> list[TrackerGap]:
        """Every gap past the bound, the one going on (if any) cut at ``now``: the run's record at its end."""
        return self.gaps + ([replace(self._open, seconds=now - self._open.since)] if self._open is not None else [])


def frames_heard(tracker) -> int:
    """Frames a pose source has received, with the body or without it (a replay's history: none)."""
    stats = getattr(tracker, "stats", None)
    return 0 if stats is None else stats.received + stats.ignored
