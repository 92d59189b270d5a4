"""The one clock of a run's MCAP recording: the tracker's (docs/service.md, "Recordings").

A robot run records on two clocks: the tracker stamps each frame with its own time, and the
service stamps what it sends and hears (commands, telemetry, link changes) with this PC's Unix
time. The two drift apart whenever either side lags: a virtual robot that climbs at 0.37x real
time, a camera's clock that is not this PC's, a service held up. Placed each on its own clock, a
command sent at a touchdown landed 31 s after the last touchdown (issue 40). So every message of
a recording is placed on the tracker's clock, and the run's start only fixes where that clock
begins in UTC:

    log time = publish time = recorded_at [UTC ns] + (t - t_first) * 1e9

``recorded_at`` the run's start (``created_at``; a replay's, its source's), ``t_first`` the tracker
time of its first frame, and ``t`` the message's tracker time [s]:

- a frame, a touchdown, a prediction (at the touchdown it predicts): its own tracker time;
- a command or a telemetry: its ``tracker_time``, the tracker time of the newest of the run's frames
  the service had received when it sent or heard it (:mod:`backend.robot.live_run`) — it lands
  after the frame it followed, never before;
- anything with a Unix time only (a link change; a command or telemetry before the run's first
  frame, or stored before runs recorded ``tracker_time``): its Unix time carried to the tracker's
  clock by :class:`TrackerClock` — linearly between the (Unix, tracker) stamp pairs of the run's
  commands and telemetry around it, one tracker second per Unix second beyond them, and with no
  pairs at all (runs stored before) by the run's start: ``t_first + (time - recorded_at)``.
"""

from __future__ import annotations

import datetime
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

NS_PER_S = 1_000_000_000


@dataclass(frozen=True)
class TrackerClock:
    """Unix time [s] to the tracker's time [s], and tracker time to a recording's log time [ns].

    ``unix`` and ``tracker``: the stamp pairs, sorted by Unix time, the tracker's made
    non-decreasing (a frame's time never goes back); ``start_ns``: the recording's start [UTC ns],
    where the tracker time ``first_frame`` [s] is placed."""

    unix: np.ndarray
    tracker: np.ndarray
    start_ns: int
    first_frame: float

    @classmethod
    def of(cls, records: Iterable[dict], recorded_at: datetime.datetime, first_frame: float) -> TrackerClock:
        """The clock of a run whose commands and telemetry are ``records`` (dicts with ``time``
        and, if recorded, ``tracker_time``), started at ``recorded_at``, its first frame at
        tracker time ``first_frame`` [s]. Without a pair, the start is the one pair."""
        pairs = sorted((r["time"], r["tracker_time"]) for r in records if r.get("tracker_time") is not None)
        start_ns = utc_ns(recorded_at)
        if not pairs:
            pairs = [(start_ns / NS_PER_S, first_frame)]
        unix, tracker = np.array(pairs, dtype=float).T
        return cls(unix, np.maximum.accumulate(tracker), start_ns, first_frame)

    def tracker_time(self, unix_time: float) -> float:
        """The tracker's time [s] of the Unix time ``unix_time`` [s]."""
        if unix_time <= self.unix[0]:
            return float(self.tracker[0] + (unix_time - self.unix[0]))
        if unix_time >= self.unix[-1]:
            return float(self.tracker[-1] + (unix_time - self.unix[-1]))
        return float(np.interp(unix_time, self.unix, self.tracker))

    def log_time(self, tracker_time: float) -> int:
        """A recording's log time [UTC ns] of the tracker time ``tracker_time`` [s]."""
        return self.start_ns + round((tracker_time - self.first_frame) * NS_PER_S)

    def record_time(self, record: dict) -> int:
        """The log time [UTC ns] of a record stamped with ``time`` [Unix s] and perhaps ``tracker_time`` [s]."""
        stamped = record.get("tracker_time")
        return self.log_time(stamped if stamped is not None else self.tracker_time(record["time"]))


def utc(moment: datetime.datetime) -> datetime.datetime:
    """A stored time as aware UTC (SQLite gives it back naive, in UTC)."""
    return moment if moment.tzinfo is not None else moment.replace(tzinfo=datetime.UTC)


def utc_ns(moment: datetime.datetime) -> int:
    """A stored time in nanoseconds since the Unix epoch (it holds microseconds: exact)."""
    epoch = datetime.datetime(1970, 1, 1, tzinfo=datetime.UTC)
    return (utc(moment) - epoch) // datetime.timedelta(microseconds=1) * 1000
