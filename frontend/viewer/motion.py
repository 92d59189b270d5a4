"""What the 3D view shows, frame by frame: sampled paths, and the pose at any instant in them.

No viser here: these are plain objects over numpy arrays, tested on their own. Everything is in SI
wall coordinates, the ones the tracker reports (docs/model.md §2): ``x`` [m] across the chute, 0 on
its centre line, positive toward the right wall; ``y`` [m] up from the chute's floor
(:data:`sim_core.climb.records.FLOOR`); ``time`` [s].

- :class:`Pose` — the robot at one instant: its body and the leg to draw;
- :class:`PathClip` — a sampled stretch of motion (one jump, or a whole stored run: tracker
  frames, a stored path) and the pose at any instant in it.

The model as a source of clips (one jump from a touchdown, the climb in real time) is
:mod:`frontend.viewer.simulated_climb`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.climb.records import Samples
from sim_core.model.walls import Wall

UNKNOWN_PHASE = -1  # tracker data: the body is seen, its legs are not
TRAIL_STRIDE = 3  # every third sample of a path is enough for a smooth trail


@dataclass(frozen=True)
class Pose:
    """The robot at one instant: the body and the leg to draw.

    ``leg_wall`` is the wall the drawn leg reaches for (a :class:`Wall`): the stance leg in stance,
    the next leg, held at its touchdown controls, in flight. ``foot_*`` and ``zeta`` [m] are NaN
    when the legs are unknown (tracker data).
    """

    time: float
    x: float
    y: float
    foot_x: float
    foot_y: float
    zeta: float
    phase: int
    leg_wall: Wall
    jump: int


@dataclass(frozen=True)
class PathClip(Samples):
    """Sampled motion (the sequencer's :class:`~sim_core.climb.records.Samples`: SI, see the module doc)
    with what the view needs beside it: per sample, the wall the drawn leg reaches for
    (``leg_wall``) and the jump (``jump``)."""

    leg_wall: np.ndarray
    jump: np.ndarray

    COLUMNS = (*Samples.COLUMNS, "leg_wall", "jump")  # so take() keeps them

    def __post_init__(self) -> None:
        if self.time.size == 0:
            raise ValueError("a path clip needs at least one sample")

    @property
    def start(self) -> float:
        return float(self.time[0])

    @property
    def end(self) -> float:
        return float(self.time[-1])

    @classmethod
    def from_body(cls, time, x, y, jump=None) -> PathClip:
        """A clip of body positions only (tracker frames): legs unknown."""
        time = np.asarray(time, dtype=float)
        nan = np.full(time.shape, math.nan)
        return cls(
            time=time,
            x=np.asarray(x, dtype=float),
            y=np.asarray(y, dtype=float),
            foot_x=nan,
            foot_y=nan,
            zeta=nan,
            phase=np.full(time.shape, UNKNOWN_PHASE),
            leg_wall=np.where(np.asarray(x) < 0, Wall.RIGHT, Wall.LEFT),
            jump=np.zeros(time.shape, dtype=int) if jump is None else np.asarray(jump),
        )

    def pose_at(self, t: float) -> Pose:
        """The pose at time ``t`` [s]: interpolated within a phase, clamped to the clip's ends."""
        i = int(np.clip(np.searchsorted(self.time, t, side="right") - 1, 0, self.time.size - 1))
        j = min(i + 1, self.time.size - 1)
        span = self.time[j] - self.time[i]
        w = 0.0 if span <= 0.0 or self.phase[i] != self.phase[j] else float(np.clip((t - self.time[i]) / span, 0, 1))

        def at(column: np.ndarray) -> float:
            return float(column[i] + w * (column[j] - column[i]))

        return Pose(
            time=float(np.clip(t, self.start, self.end)),
            x=at(self.x),
            y=at(self.y),
            foot_x=at(self.foot_x),
            foot_y=at(self.foot_y),
            zeta=at(self.zeta),
            phase=int(self.phase[i]),
            leg_wall=Wall(int(self.leg_wall[i])),
            jump=int(self.jump[i]),
        )

    def sampled_at(self, times) -> PathClip:
        """:meth:`pose_at` at each of ``times`` [s] (ascending), as a clip: row k is the pose at
        ``times[k]`` (its ``time`` clamped to the clip's ends, as the pose's is)."""
        t = np.asarray(times, dtype=float)
        last = self.time.size - 1
        i = np.clip(np.searchsorted(self.time, t, side="right") - 1, 0, last)
        j = np.minimum(i + 1, last)
        span = self.time[j] - self.time[i]
        within = (span > 0.0) & (self.phase[i] == self.phase[j])
        w = np.where(within, np.clip((t - self.time[i]) / np.where(span > 0.0, span, 1.0), 0, 1), 0.0)

        def at(column: np.ndarray) -> np.ndarray:
            return column[i] + w * (column[j] - column[i])

        return PathClip(
            time=np.clip(t, self.start, self.end),
            x=at(self.x),
            y=at(self.y),
            foot_x=at(self.foot_x),
            foot_y=at(self.foot_y),
            zeta=at(self.zeta),
            phase=self.phase[i],
            leg_wall=self.leg_wall[i],
            jump=self.jump[i],
        )

    def body_until(self, t: float, *, since: float = -math.inf) -> np.ndarray:
        """Body positions sampled in ``[since, t]``, shape (n, 2): the trail."""
        lo, hi = np.searchsorted(self.time, [since, t], side="right")
        lo = max(lo - 1, 0) if since > -math.inf else 0
        return np.column_stack([self.x[lo:hi], self.y[lo:hi]])
