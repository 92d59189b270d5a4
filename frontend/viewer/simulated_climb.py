"""The model as the 3D view's source of motion: one jump from a touchdown, and the climb in real time.

No viser here. Each jump is simulated by the climb sequencer (:mod:`sim_core.climb.sequencer`, which the
virtual robot runs too) and drawn as a :class:`~frontend.viewer.motion.PathClip` (SI wall
coordinates, docs/model.md §2).

- :class:`JumpPlan` — one simulated jump and its clip;
- :func:`model_jump` — one jump of the model from a touchdown (live mode's ghost; in a world:
  :func:`frontend.viewer.world_ghost.world_jump`);
- :class:`Controls` — what simulate mode's sliders set: both legs and the robot;
- :class:`SimulatedClimb` — the model climbing in real time, each jump with the controls of the
  moment it starts, the next leg read at lift-off as the robot does, ending at a failing jump, at
  the chute's floor (docs/model.md §7) or at its top; with a law set (:meth:`SimulatedClimb.set_law`), the
  loop closed as on the robot: at each touchdown the law sets the next touchdown's leg.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from frontend.viewer.motion import PathClip, Pose
from sim_core import LegControl, PhysicalParams
from sim_core.climb import sequencer as climb
from sim_core.climb.records import CHUTE_TOP, ClimbSetup, End, Jump, JumpStart, NextLeg, Samples
from sim_core.control.design import SteppedLaw
from sim_core.control.laws import Controller
from sim_core.model.trajectory import STANCE
from sim_core.model.walls import Wall


@dataclass(frozen=True)
class JumpPlan:
    """One simulated jump (:class:`sim_core.climb.records.Jump`) and its clip, for drawing.

    Attributes:
        jump: the sequencer's jump: its touchdown, the leg in flight, how it ended.
        robot: the robot the jump was simulated for (the sliders' at its touchdown).
        clip: the jump's samples, touchdown to the next touchdown (or to the end of the climb).
    """

    jump: Jump
    robot: PhysicalParams
    clip: PathClip

    @classmethod
    def of(cls, jump: Jump, robot: PhysicalParams, samples: Samples | None = None) -> JumpPlan:
        """``jump`` drawn from its own samples, or from ``samples`` (its samples with more beside them)."""
        samples, wall = jump.samples if samples is None else samples, jump.wall
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
        """Why the climb ended in this jump (a ``Failure``, ``ClimbEnd.FLOOR`` or ``ClimbEnd.TOP``), or None."""
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


def _chute(robot: PhysicalParams) -> ClimbSetup:
    """A simulated climb's setup: it ends at the lab's chute's top, as the table does (an open loop
    climbed to 9.8 m in a 2 m chute)."""
    return ClimbSetup(robot, top=CHUTE_TOP)


@dataclass(frozen=True)
class Controls:
    """What the sliders set: both legs' touchdown controls and the robot."""

    left: LegControl
    right: LegControl
    robot: PhysicalParams

    def leg_for(self, wall: Wall) -> LegControl:
        return self.left if wall == Wall.LEFT else self.right


@dataclass(frozen=True)
class LawCommand:
    """What the law commanded at touchdown ``jump``: the next touchdown's leg, and whether it was
    clipped to the leg's range."""

    jump: int
    leg: LegControl
    clipped: bool


class SimulatedClimb:
    """The model climbing between the walls in real time: a driver of :mod:`sim_core.climb.sequencer`.

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
        self._law: Controller | None = None
        self.reset(state)

    def reset(self, state: tuple[float, float] | None = None) -> None:
        """Back to the floor: touchdown 0 on the left wall, the foot at the floor, at time 0 (a law
        set starts afresh: its memory from touchdown 0's controls)."""
        with self._lock:
            self._start_state = state or self._start_state
            controls = self._controls
            first = controls.leg_for(Wall.LEFT)
            start = climb.launch(_chute(controls.robot), first, self._start_state)
            self.stepped = None if self._law is None else SteppedLaw(self._law, first)
            self.commands: list[LawCommand] = []
            self.plans: list[JumpPlan] = []
            self._plan(start)

    def set_law(self, law: Controller | None) -> None:
        """Close the loop with ``law`` (its target in l0 above the floor), or open it (None); from
        the next :meth:`reset`."""
        self._law = law

    @property
    def law(self) -> Controller | None:
        return self._law

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
                self._plan(climb.touchdown_after(_chute(plan.robot), plan.jump))

    def next_touchdown_time(self, t: float) -> float:
        """[s] when the jump under way at ``t`` ends (for stepping one jump)."""
        self.pose_at(t)
        return self.current.clip.end

    def _plan(self, start: JumpStart) -> None:
        """Jump ``start`` planned with the next leg's controls of now (read again at lift-off); closed
        loop, the law's command from this touchdown."""
        controls = self._controls
        setup = _chute(controls.robot)
        if self.stepped is not None:
            self._command(start, controls.robot)
        next_leg = climb.read_next_leg(start, self._next_leg_for(start))
        self.plans.append(JumpPlan.of(climb.jump(setup, start, next_leg), controls.robot))
        self._next_leg_read = False

    def _command(self, start: JumpStart, robot: PhysicalParams) -> None:
        """The law at touchdown ``start``: what it shows (height above the floor and pitch, as the
        robot's tracker gives them, and the section state) sets the next touchdown's leg."""
        psi0, zeta0, clipped = self.stepped.step(start.body_height / robot.leg_length, start.pitch, *start.state,
                                                 start.wall.other == Wall.LEFT)  # fmt: skip
        self.commands.append(LawCommand(start.jump, LegControl(psi0, zeta0), clipped))

    def _next_leg_for(self, start: JumpStart) -> LegControl:
        """The next wall's leg as commanded now: the law's command from this touchdown, else the sliders'."""
        if self.stepped is not None and self.commands and self.commands[-1].jump == start.jump:
            return self.commands[-1].leg
        return self._controls.leg_for(start.wall.other)

    def _read_next_leg(self) -> None:
        """At lift-off the flight toward the other wall takes that leg's controls of now."""
        self._next_leg_read = True
        plan = self.current
        next_leg = climb.read_next_leg(plan.jump.start, self._next_leg_for(plan.jump.start))
        replanned = climb.replan(_chute(plan.robot), plan.jump, next_leg)
        if replanned is not plan.jump:
            self.plans[-1] = JumpPlan.of(replanned, plan.robot)
