"""What a climb is made of: its setup, each touchdown, the leg read at lift-off, the sampled motion,
each jump, and how a climb ends (docs/model.md §7).

The frozen records the climb sequencer (:mod:`sim_core.climb.sequencer`) hands from call to call and its
drivers — the 3D view, the virtual robot — read. No simulation here.

Units and frame (SI, the tracker's): ``x`` [m] across the chute, 0 on its centre line, positive
toward the right wall; ``y`` [m] up from the chute's floor (:data:`FLOOR`); ``time`` [s] from the
first touchdown. Section states stay nondimensional and flipped (docs/model.md §4).

``ClimbEnd`` is not a :class:`sim_core.model.failures.Failure`: those are the kernels' status codes, and
MJTF's outcome histogram lists every one of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from sim_core.model.controls import LegControl
from sim_core.model.failures import Failure
from sim_core.model.params import PhysicalParams
from sim_core.model.walls import Wall
from sim_core.world.world import World

FLOOR = 0.0  # [m] the chute's floor: the height of the first foot's touchdown
# [m] the top of the lab's chute, its air table's length up the slope (the paper's climbs end there,
# §VI.D): the highest height a controller may be asked to hold, in every front end.
CHUTE_TOP = 2.0
SAMPLE_RATE = 200.0  # path samples per sqrt(l0/g): ~2.4 ms for the paper's robot


class ClimbEnd(Enum):
    """Why a climb ended other than a failing jump (:class:`sim_core.model.failures.Failure`)."""

    FLOOR = "floor"
    TOP = "top"

    @property
    def code(self) -> str:
        return self.value

    @property
    def message(self) -> str:
        return _MESSAGES[self]


_MESSAGES = {
    ClimbEnd.FLOOR: "the body reached the chute's floor",
    ClimbEnd.TOP: f"the body reached the chute's top ({CHUTE_TOP:g} m): the lab's table ends there",
}

End = Failure | ClimbEnd


@dataclass(frozen=True)
class ClimbSetup:
    """What every jump of a climb shares: the robot, the sampling, the floor and (None: none) a top,
    which a jump landing above ends the climb at (:attr:`ClimbEnd.TOP`)."""

    robot: PhysicalParams
    sample_rate: float = SAMPLE_RATE  # per sqrt(l0/g)
    floor: float = FLOOR  # [m]
    top: float | None = None  # [m]
    world: World | None = None  # the chute (docs/model.md §8); None: parallel walls the robot's d apart


@dataclass(frozen=True)
class JumpStart:
    """A touchdown, where jump ``jump`` begins.

    Attributes:
        jump: 0-based jump index; wall: the stance wall (``wall_of(jump)`` in a climb).
        time: [s]; body_height: [m] above the floor.
        state: ``(xdot, ydot)`` section state, nondimensional, flipped (docs/model.md §4).
        leg: the stance leg's controls as realised (noise included); pitch: body pitch [rad].
        body_x: [m] the body's x at touchdown in a world (NaN on parallel walls, where the legs
            set it); segment: the foot's segment of the stance side (docs/model.md §8).
    """

    jump: int
    wall: Wall
    time: float
    body_height: float
    state: tuple[float, float]
    leg: LegControl
    pitch: float = 0.0
    body_x: float = math.nan
    segment: int = 0


@dataclass(frozen=True)
class NextLeg:
    """The leg reaching for the next wall, as read at lift-off: realised controls and the pitch [rad]."""

    leg: LegControl
    pitch: float = 0.0


@dataclass(frozen=True)
class Samples:
    """Sampled motion in SI wall coordinates, columns of one length in time order.

    ``foot_*`` [m] are the stance foot in stance and the next leg's foot in flight; ``zeta`` [m]
    the drawn leg's length; ``phase`` is STANCE or FLIGHT.
    """

    time: np.ndarray
    x: np.ndarray
    y: np.ndarray
    foot_x: np.ndarray
    foot_y: np.ndarray
    zeta: np.ndarray
    phase: np.ndarray

    COLUMNS = ("time", "x", "y", "foot_x", "foot_y", "zeta", "phase")

    def __len__(self) -> int:
        return int(self.time.size)

    def take(self, rows) -> Samples:
        """The rows ``rows`` (a slice, mask or index array) of every column."""
        return type(self)(**{name: getattr(self, name)[rows] for name in self.COLUMNS})


@dataclass(frozen=True)
class Stance:
    """The stance part of a jump: its samples, and how the climb ended if it did there."""

    start: JumpStart
    samples: Samples
    end: End | None


@dataclass(frozen=True)
class Jump:
    """One jump, touchdown to the next touchdown (or to the end of the climb).

    Attributes:
        start, next: this jump's touchdown and the leg that flies to the next wall.
        samples: the whole jump; ``liftoff`` indexes its first flight sample (its length if none).
        end: why the climb ended in this jump (a jump failure or the floor), or None.
        rise: [m] foot height gained; duration: [s] to the next touchdown (NaN after an end).
        arrival: section state at the next touchdown, before process noise; None after an end.
        landing: in a world, the next touchdown's body x [m] and segment; None otherwise.
    """

    start: JumpStart
    next: NextLeg
    samples: Samples
    liftoff: int
    end: End | None
    rise: float
    duration: float
    arrival: tuple[float, float] | None
    landing: tuple[float, int] | None = None

    @property
    def wall(self) -> Wall:
        return self.start.wall

    @property
    def stance(self) -> Samples:
        return self.samples.take(slice(0, self.liftoff))

    @property
    def flight(self) -> Samples:
        return self.samples.take(slice(self.liftoff, None))

    @property
    def liftoff_time(self) -> float:
        """[s] the first flight sample (the last sample when the climb ended in stance)."""
        index = min(self.liftoff, len(self.samples) - 1)
        return float(self.samples.time[index])
