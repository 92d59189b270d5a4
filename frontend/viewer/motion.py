"""What the 3D view shows, frame by frame: sampled paths and the sources that produce them.

No viser here: these are plain objects over numpy arrays, tested on their own. Everything is in SI
wall coordinates, the ones the tracker reports (docs/model.md §2): ``x`` [m] across the chute, 0 on
its centre line, positive toward the right wall; ``y`` [m] up from the chute's floor
(:data:`sim_core.climb.FLOOR`); ``time`` [s].

- :class:`PathClip` — a sampled stretch of motion (one jump, or a whole stored run) and the pose
  at any instant in it;
- :func:`model_jump` — one jump of the model from a touchdown, as a clip (by
  :func:`sim_core.climb.jump`, the sequencer the virtual robot runs too);
- :class:`SimulatedClimb` — the model climbing in real time, each jump with the controls of the
  moment it starts, the next leg read at lift-off as the robot does, ending at a failing jump or
  at the chute's floor (:mod:`sim_core.climb`).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np

from sim_core import LegControl, PhysicalParams, climb
from sim_core.climb import ClimbSetup, End, Jump, JumpStart, NextLeg, Samples
from sim_core.trajectory import STANCE
from sim_core.walls import Wall

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
    """Sampled motion (the sequencer's :class:`~sim_core.climb.Samples`: SI, see the module doc)
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


@dataclass(frozen=True)
class JumpPlan:
    """One simulated jump (:class:`sim_core.climb.Jump`) and its clip, for drawing.

    Attributes:
        jump: the sequencer's jump: its touchdown, the leg in flight, how it ended.
        robot: the robot the jump was simulated for (the sliders' at its touchdown).
        clip: the jump's samples, touchdown to the next touchdown (or to the end of the climb).
    """

    jump: Jump
    robot: PhysicalParams
    clip: PathClip

    @classmethod
    def of(cls, jump: Jump, robot: PhysicalParams) -> JumpPlan:
        samples, wall = jump.samples, jump.wall
        clip = PathClip(
            **{name: getattr(samples, name) for name in Samples.COLUMNS},
            leg_wall=np.where(samples.phase == STANCE, wall, wall.other),
            jump=np.full(samples.time.shape, jump.start.jump),
        )
        return cls(jump, robot, clip)

    @property
    def wall(self) -> Wall:
        return self.jump.wall

    @property
    def leg(self) -> LegControl:
        return self.jump.start.leg

    @property
    def next_leg(self) -> LegControl:
        return self.jump.next.leg

    @property
    def state(self) -> tuple[float, float]:
        """The section state at this jump's touchdown (nondimensional, flipped frame)."""
        return self.jump.start.state

    @property
    def liftoff_time(self) -> float:
        return self.jump.liftoff_time

    @property
    def rise(self) -> float:
        """[m] foot height gained (NaN when the climb ended in this jump)."""
        return self.jump.rise

    @property
    def failure(self) -> End | None:
        """Why the climb ended in this jump (a ``Failure`` or ``ClimbEnd.FLOOR``), or None."""
        return self.jump.end

    @property
    def next_height(self) -> float:
        """[m] body height at the next touchdown (the last sample's after an end)."""
        if self.jump.end is not None:
            return float(self.clip.y[-1])
        return climb.touchdown_after(ClimbSetup(self.robot), self.jump).body_height


def model_jump(
    robot: PhysicalParams,
    state: tuple[float, float],
    leg: LegControl,
    next_leg: LegControl,
    *,
    wall: Wall,
    start_time: float,
    start_height: float,
    jump_index: int = 0,
) -> JumpPlan:
    """One jump of the model from a touchdown on ``wall`` with section state ``state``.

    Args:
        state: ``(xdot, ydot)`` at touchdown, nondimensional and flipped (docs/model.md §2).
        start_time: [s] the touchdown's time; start_height: [m] the body height there.
    """
    start = JumpStart(jump_index, Wall(wall), start_time, start_height, (float(state[0]), float(state[1])), leg)
    return JumpPlan.of(climb.jump(ClimbSetup(robot), start, NextLeg(next_leg)), robot)


@dataclass(frozen=True)
class Controls:
    """What the sliders set: both legs' touchdown controls and the robot."""

    left: LegControl
    right: LegControl
    robot: PhysicalParams

    def leg_for(self, wall: Wall) -> LegControl:
        return self.left if wall == Wall.LEFT else self.right


class SimulatedClimb:
    """The model climbing between the walls in real time: a driver of :mod:`sim_core.climb`.

    Jump ``k`` is simulated when the playback reaches its touchdown, with the controls and robot
    of that moment; the leg reaching for the next wall is read again at lift-off, as the robot's
    firmware does, so a slider moved mid-jump shows at the next touchdown. The climb ends at a
    failing jump or when the body reaches the floor. ``pose_at`` is called from the view's loop,
    ``set_controls`` from GUI callbacks.
    """

    def __init__(self, controls: Controls, state: tuple[float, float]):
        self._lock = threading.Lock()
        self._controls = controls
        self._start_state = state
        self.reset(state)

    def reset(self, state: tuple[float, float] | None = None) -> None:
        """Back to the floor: touchdown 0 on the left wall, the foot at the floor, at time 0."""
        with self._lock:
            self._start_state = state or self._start_state
            controls = self._controls
            start = climb.launch(ClimbSetup(controls.robot), controls.leg_for(Wall.LEFT), self._start_state)
            self.plans: list[JumpPlan] = []
            self._plan(start)

    @property
    def controls(self) -> Controls:
        return self._controls

    def set_controls(self, controls: Controls) -> None:
        """Used from the next touchdown on (the next leg: from the next lift-off)."""
        self._controls = controls

    @property
    def current(self) -> JumpPlan:
        return self.plans[-1]

    @property
    def ended(self) -> bool:
        return self.current.failure is not None

    def pose_at(self, t: float) -> Pose:
        """The pose at playback time ``t`` [s], simulating the jumps up to it."""
        with self._lock:
            while True:
                plan = self.current
                if t >= plan.liftoff_time and not self._next_leg_read:
                    self._read_next_leg()
                    plan = self.current
                if plan.failure is not None or t < plan.clip.end:
                    return plan.clip.pose_at(t)
                # The leg that touches down is the one that flew: its controls were fixed at lift-off.
                self._plan(climb.touchdown_after(ClimbSetup(plan.robot), plan.jump))

    def next_touchdown_time(self, t: float) -> float:
        """[s] when the jump under way at ``t`` ends (for stepping one jump)."""
        self.pose_at(t)
        return self.current.clip.end

    def _plan(self, start: JumpStart) -> None:
        """Jump ``start`` planned with the next leg's controls of now (read again at lift-off)."""
        controls = self._controls
        setup = ClimbSetup(controls.robot)
        next_leg = climb.read_next_leg(start, controls.leg_for(start.wall.other))
        self.plans.append(JumpPlan.of(climb.jump(setup, start, next_leg), controls.robot))
        self._next_leg_read = False

    def _read_next_leg(self) -> None:
        """At lift-off the flight toward the other wall takes that leg's controls of now."""
        self._next_leg_read = True
        plan = self.current
        next_leg = climb.read_next_leg(plan.jump.start, self._controls.leg_for(plan.wall.other))
        replanned = climb.replan(ClimbSetup(plan.robot), plan.jump, next_leg)
        if replanned is not plan.jump:
            self.plans[-1] = JumpPlan.of(replanned, plan.robot)
