"""What the 3D view shows, frame by frame: sampled paths and the sources that produce them.

No viser here: these are plain objects over numpy arrays, tested on their own. Everything is in SI
wall coordinates, the ones the tracker reports (model.md §2): ``x`` [m] across the chute, 0 on its
centre line, positive toward the right wall; ``y`` [m] up, 0 at the first touchdown's body height
for simulations and at the floor for tracker data; ``time`` [s].

- :class:`PathClip` — a sampled stretch of motion (one jump, or a whole stored run) and the pose
  at any instant in it;
- :func:`model_jump` — one jump of the model from a touchdown, as a clip (the one call of the
  simulator the view makes: ``sim_core.simulate_trajectory``);
- :class:`SimulatedClimb` — the model climbing in real time, each jump with the controls of the
  moment it starts, the next leg read at lift-off as the robot does.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np

from sim_core import ControlSchedule, LegControl, PhysicalParams, simulate_trajectory
from sim_core.failures import Failure
from sim_core.trajectory import FLIGHT, STANCE

LEFT, RIGHT = -1, +1  # walls, as backend.robot.touchdown numbers them (the left wall is at x < 0)
UNKNOWN_PHASE = -1  # tracker data: the body is seen, its legs are not
SAMPLES_PER_TIME_UNIT = 200.0  # path samples per sqrt(l0/g): ~2.4 ms for the paper's robot
START_HEIGHT = 0.15  # [m] body height at a simulation's first touchdown, above the floor


@dataclass(frozen=True)
class Pose:
    """The robot at one instant: the body and the leg to draw.

    ``leg_wall`` is the wall the drawn leg reaches for (LEFT or RIGHT): the stance leg in stance,
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
    leg_wall: int
    jump: int


@dataclass(frozen=True)
class PathClip:
    """Sampled motion, columns of one length in time order (SI; see the module doc)."""

    time: np.ndarray
    x: np.ndarray
    y: np.ndarray
    foot_x: np.ndarray
    foot_y: np.ndarray
    zeta: np.ndarray
    phase: np.ndarray
    leg_wall: np.ndarray
    jump: np.ndarray

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
            leg_wall=np.where(np.asarray(x) < 0, RIGHT, LEFT),
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
            leg_wall=int(self.leg_wall[i]),
            jump=int(self.jump[i]),
        )

    def body_until(self, t: float, *, since: float = -math.inf) -> np.ndarray:
        """Body positions sampled in ``[since, t]``, shape (n, 2): the trail."""
        lo, hi = np.searchsorted(self.time, [since, t], side="right")
        lo = max(lo - 1, 0) if since > -math.inf else 0
        return np.column_stack([self.x[lo:hi], self.y[lo:hi]])


@dataclass(frozen=True)
class JumpPlan:
    """One simulated jump: its clip and what it leads to.

    Attributes:
        clip: the jump's samples, touchdown to the next touchdown (or to the failure).
        robot: the robot the jump was simulated for (the sliders' at its touchdown).
        leg, next_leg: the controls of the stance leg and of the leg reaching for the next wall.
        wall: the stance wall, LEFT or RIGHT.
        state: the section state at this jump's touchdown (nondimensional, flipped frame).
        next_state: the section state at the next touchdown; None after a failure.
        liftoff_time: [s] the first flight sample (the end for a failed stance).
        rise: [m] foot height gained (NaN after a failure).
        failure: why the jump failed, or None.
    """

    clip: PathClip
    robot: PhysicalParams
    leg: LegControl
    next_leg: LegControl
    wall: int
    state: tuple[float, float]
    start_height: float
    next_state: tuple[float, float] | None
    liftoff_time: float
    rise: float
    failure: Failure | None

    @property
    def next_height(self) -> float:
        """[m] body height at the next touchdown."""
        return self.clip.y[-1]


def model_jump(
    robot: PhysicalParams,
    state: tuple[float, float],
    leg: LegControl,
    next_leg: LegControl,
    *,
    wall: int,
    start_time: float,
    start_height: float,
    jump_index: int = 0,
) -> JumpPlan:
    """One jump of the model from a touchdown on ``wall`` with section state ``state``.

    Args:
        state: ``(xdot, ydot)`` at touchdown, nondimensional and flipped (model.md §2).
        start_time: [s] the touchdown's time; start_height: [m] the body height there.
    """
    path = simulate_trajectory(
        robot.to_model(),
        ControlSchedule.of(leg, next_leg),
        state,
        1,
        sample_rate=SAMPLES_PER_TIME_UNIT,
        start_height=start_height / robot.leg_length,
    ).to_si(robot)
    mirror = -1.0 if wall == RIGHT else 1.0  # the simulator puts the first stance on the left wall
    clip = PathClip(
        time=start_time + path.time,
        x=mirror * path.x,
        y=path.y,
        foot_x=mirror * path.foot_x,
        foot_y=path.foot_y,
        zeta=path.zeta,
        phase=path.phase.astype(int),
        leg_wall=np.where(path.phase == STANCE, wall, -wall),
        jump=np.full(path.time.shape, jump_index),
    )
    flight = np.flatnonzero(path.phase == FLIGHT)
    completed = path.failure is None
    return JumpPlan(
        clip=clip,
        robot=robot,
        leg=leg,
        next_leg=next_leg,
        wall=wall,
        state=(float(state[0]), float(state[1])),
        start_height=start_height,
        next_state=tuple(path.section_states[-1] / robot.scales.velocity) if completed else None,
        liftoff_time=float(clip.time[flight[0]]) if flight.size else clip.end,
        rise=float(path.rises[0]) if completed else math.nan,
        failure=path.failure,
    )


@dataclass(frozen=True)
class Controls:
    """What the sliders set: both legs' touchdown controls and the robot."""

    left: LegControl
    right: LegControl
    robot: PhysicalParams

    def leg_for(self, wall: int) -> LegControl:
        return self.left if wall == LEFT else self.right


class SimulatedClimb:
    """The model climbing between the walls in real time.

    Jump ``k`` (from 0, the first on the left wall) is simulated when the playback reaches its
    touchdown, with the controls and robot of that moment; the leg reaching for the next wall is
    read again at lift-off, as the robot's firmware does, so a slider moved mid-jump shows at the
    next touchdown. ``pose_at`` is called from the view's loop, ``set_controls`` from GUI callbacks.
    """

    def __init__(self, controls: Controls, state: tuple[float, float]):
        self._lock = threading.Lock()
        self._controls = controls
        self._start_state = state
        self.reset(state)

    def reset(self, state: tuple[float, float] | None = None) -> None:
        """Back to the floor: touchdown 0 on the left wall at START_HEIGHT and time 0."""
        with self._lock:
            self._start_state = state or self._start_state
            self.plans: list[JumpPlan] = []
            self._next_leg_read = False
            self._plan(self._start_state, start_time=0.0, start_height=START_HEIGHT)

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
                self._plan(plan.next_state, start_time=plan.clip.end, start_height=plan.next_height, leg=plan.next_leg)

    def next_touchdown_time(self, t: float) -> float:
        """[s] when the jump under way at ``t`` ends (for stepping one jump)."""
        self.pose_at(t)
        return self.current.clip.end

    def _plan(self, state, *, start_time: float, start_height: float, leg: LegControl | None = None) -> None:
        k = len(self.plans)
        wall = LEFT if k % 2 == 0 else RIGHT
        controls = self._controls
        self.plans.append(
            model_jump(
                controls.robot,
                state,
                leg or controls.leg_for(wall),
                controls.leg_for(-wall),
                wall=wall,
                start_time=start_time,
                start_height=start_height,
                jump_index=k,
            )
        )
        self._next_leg_read = False

    def _read_next_leg(self) -> None:
        """At lift-off the flight toward the other wall takes that leg's controls of now."""
        self._next_leg_read = True
        plan = self.current
        next_leg = self._controls.leg_for(-plan.wall)
        if next_leg == plan.next_leg or plan.liftoff_time == plan.clip.end:  # unchanged, or never left the wall
            return
        # The stance is the same (it does not depend on the next leg); the flight ends elsewhere.
        self.plans[-1] = model_jump(
            plan.robot,
            plan.state,
            plan.leg,
            next_leg,
            wall=plan.wall,
            start_time=plan.clip.start,
            start_height=plan.start_height,
            jump_index=len(self.plans) - 1,
        )
