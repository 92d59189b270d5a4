"""A live run that follows a plan (a ``plan`` job's, in the world the robot climbs): the
foot-placement law of :mod:`sim_core.planning.live` stepped once per detected touchdown by the
run's loop (its one owner, the loop's thread), in the place of a height controller
(:mod:`backend.robot.live_law`, whose interface it shares).

At detected touchdown ``i`` — the climb's touchdown ``i + 1``, the plan's row ``i + 1`` — the law
checks the foot is on the plan's foothold, predicts the stance's lift-off from the touchdown seen,
and sends the leg that lands on the plan's next foothold: turned back by the tracked pitch, less its
leg's servo offset, within the servos' range. Each command is journaled with its target foothold.
The run ends — disarmed, like every ending — when a foot reaches the plan's goal (``goal reached``,
a clean ending), lands off its foothold (``missed foothold: ...``) or when no leg lands on the next
one (``off plan: ...``): the law raises :class:`RunEnds` with the reason, and the loop ends there.
There is no replanning on the robot (yet): off its plan, the run stops rather than improvise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from backend.robot.limits import ServoLimits
from backend.robot.run_endings import GOAL_REACHED, MISSED_FOOTHOLD, OFF_PLAN, RunEnds
from backend.robot.touchdown import Touchdown
from sim_core.model.controls import NO_OFFSETS, LegControl, LegOffsets
from sim_core.model.failures import OK, Failure
from sim_core.model.walls import Wall
from sim_core.world.world import SIDES

if TYPE_CHECKING:  # the law's kernels load with its plan, never with the API (tests/backend/api/test_app.py)
    from sim_core.planning.live import LivePlan

NO_LEG, PLACED = 0, 2  # sim_core.control.placement's OFF_PLAN and PLACED (a test checks they agree)


@dataclass
class PlanLaw:
    """``plan`` (a :class:`~sim_core.planning.live.LivePlan`) to a foot at ``goal_m`` [m] on a robot of
    ``leg_length`` [m]; the legs' servo ``offsets`` and ``limits`` as :class:`backend.robot.live_law.LiveLaw`."""

    plan: LivePlan
    goal_m: float
    leg_length: float  # [m]
    offsets: LegOffsets = NO_OFFSETS
    limits: ServoLimits = field(default_factory=ServoLimits)
    name: str = "plan"

    def __post_init__(self) -> None:
        # Each touchdown's leg as sent, before the offsets (the plan's own for touchdowns 0 and 1), by
        # row: turned by the pitch the robot has when it lands, it is the leg as realised.
        self.meant = {row: (math.radians(step["psi0_deg"]), step["zeta0"]) for row, step in
                      enumerate(self.plan.steps[:2])}  # fmt: skip
        self._psi0_offset = tuple(math.radians(offset) for offset in self.offsets.psi0_offset_deg)

    def warm(self) -> None:
        """Compile the law's kernels (before the run starts: its first touchdown must not wait for them)."""
        step = self.plan.steps[0]
        psi0, zeta0 = self.meant[0]
        foot_x, foot_y = step["target"]
        body = (foot_x + zeta0 * math.cos(psi0), foot_y + zeta0 * math.sin(psi0))
        self.plan.next_leg(0, body, tuple(step["velocity"]), 0, (psi0, zeta0))

    def start_legs(self) -> list[LegControl]:
        """The run's start controls [left, right]: the plan's touchdowns 0 and 1, less the legs' offsets."""
        return [self._sent(side, *self.meant[side])[0] for side in (0, 1)]

    def command(self, touchdown: Touchdown, pitch: float, leg_psi0: float) -> tuple[LegControl, dict]:
        """The next touchdown's controls after detected ``touchdown`` (``pitch`` [rad] tracked in its
        stance, NaN: none) and what the journal keeps of it; :class:`RunEnds` where the run ends."""
        row, side = touchdown.index + 1, 0 if touchdown.wall == Wall.LEFT else 1
        pitch = 0.0 if not math.isfinite(pitch) else pitch
        foot_y = touchdown.foot_height / self.leg_length
        planned_side, planned, target = self.plan.planned(min(row, len(self.plan.steps) - 1))
        if foot_y >= self.goal_m / self.leg_length:
            raise RunEnds(f"{GOAL_REACHED}: touchdown {row}'s foot at {touchdown.foot_height:.3f} m")
        landed = self.plan.segment_of(side, foot_y)
        if row < len(self.plan.steps) and (landed, side) != (planned, planned_side):
            raise RunEnds(f"{MISSED_FOOTHOLD}: touchdown {row} on the {SIDES[side]} side's segment {landed} "
                          f"(foot at {touchdown.foot_height:.3f} m), planned segment {planned}")  # fmt: skip
        psi0, zeta0 = self.meant.get(row, (math.nan, math.nan))
        realised = (psi0 + (pitch if side == 0 else -pitch), zeta0)
        body = (touchdown.body_x / self.leg_length, touchdown.body_height / self.leg_length)
        velocity = (-int(touchdown.wall) * touchdown.state[0], touchdown.state[1])  # unflipped: wall coordinates
        placed = self.plan.next_leg(row, body, velocity, side, realised)
        if placed.status != OK:
            failure = Failure(placed.status).code
            raise RunEnds(f"{OFF_PLAN}: the stance of touchdown {row} is predicted to fail ({failure})")
        if placed.found == NO_LEG:
            why = "the plan ends below its goal" if row + 1 >= len(self.plan.steps) else "no leg lands on it"
            raise RunEnds(f"{OFF_PLAN}: after touchdown {row}, {why} (foothold {placed.segment} of the "
                          f"{SIDES[placed.side]} side)")  # fmt: skip
        turned = placed.psi0 - (pitch if placed.side == 0 else -pitch)  # the leg is fixed to the pitched body
        self.meant[row + 1] = (turned, placed.zeta0)
        control, clipped = self._sent(placed.side, turned, placed.zeta0)
        target = {"touchdown": row + 1, "side": SIDES[placed.side], "segment": placed.segment,
                  "x_m": placed.target[0] * self.leg_length, "y_m": placed.target[1] * self.leg_length}  # fmt: skip
        journal = {"controller": self.name, "clipped": clipped, "target": target,
                   "placed": "placed" if placed.found == PLACED else "tight"}  # fmt: skip
        return control, journal

    def _sent(self, side: int, psi0: float, zeta0: float) -> tuple[LegControl, bool]:
        """The leg ``(psi0, zeta0)`` meant for ``side`` as commanded: less the leg's offsets, held to
        the servos' range; and whether it was clipped."""
        held, clipped = self.limits.held(psi0 - self._psi0_offset[side], zeta0 - self.offsets.zeta0_offset[side])
        return LegControl(*held), clipped
