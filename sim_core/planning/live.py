"""A plan followed live, one touchdown at a time: what the robot's loop asks of the foot-placement
law at each touchdown it detects (backend/robot/plan_law.py), with the law of the simulated
trials (:mod:`sim_core.planning.follow`): the stance run from the touchdown seen, then the leg
that lands on the plan's next foothold decided at its lift-off
(:func:`sim_core.control.placement.place_from_liftoff`).

On the robot the leg is positioned during the stance, before the lift-off can be seen, so the
lift-off is the model's prediction from the touchdown — where the simulated law tracks it. The
plan comes as ``parkour plan --json`` gives its steps (the plan job's result); coordinates are
wall coordinates in ``l0``, angles in radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.control.placement import AIM_SIZE, OFF_PLAN, place_from_liftoff
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelParams
from sim_core.planning.follow import (
    LIFT_X,
    LIFT_YDOT,
    PSI0,
    SEGMENT,
    SIDE,
    TRIAL_SIZE,
    XDOT,
    YDOT,
    ZETA0,
    X,
    Y,
    lift_off_from,
)
from sim_core.world.geometry import SideArrays, pack, segment_at, side_x
from sim_core.world.world import SIDES, World


@dataclass(frozen=True)
class Placement:
    """The law's answer after a touchdown: ``status`` (OK, or the failure's code where the stance
    itself fails), ``found`` (placement's PLACED, TIGHT or OFF_PLAN), the next leg ``(psi0,
    zeta0)`` [rad, l0] in the landing side's stance frame before any pitch correction, and the
    foothold aimed at."""

    status: int
    found: int
    psi0: float
    zeta0: float
    side: int
    segment: int
    target: tuple[float, float]


@dataclass(frozen=True)
class LivePlan:
    """A plan's aims (row ``k`` for touchdown ``k``), its world packed, the model's record and the
    law's settings."""

    aims: np.ndarray
    sides: SideArrays
    model: np.ndarray
    settings: np.ndarray
    steps: tuple[dict, ...]

    @classmethod
    def of(cls, model: ModelParams, world: World, steps: list[dict], settings: PlacementSettings | None = None):
        """From ``parkour plan --json``'s ``plan`` (each step's ``segment``, ``target``, ``velocity``,
        ``psi0_deg``, ``zeta0``)."""
        aims = np.full((len(steps), AIM_SIZE), math.nan)
        for k, step in enumerate(steps):
            leg = (math.radians(step["psi0_deg"]), step["zeta0"])
            aims[k, :7] = (step["segment"], *step["target"], *step["velocity"], *leg)
            if k > 0:
                aims[k - 1, 7:] = (*leg, step["target"][1], *step["velocity"], step["segment"])
        return cls(aims, pack(world, model.mu), model.record(), (settings or PlacementSettings()).array(),
                   tuple(steps))  # fmt: skip

    def planned(self, row: int) -> tuple[int, int, tuple[float, float]]:
        """Touchdown ``row``'s foothold as planned: side (0 left, 1 right), segment, target."""
        step = self.steps[row]
        return SIDES.index(step["side"]), int(step["segment"]), (float(step["target"][0]), float(step["target"][1]))

    def segment_of(self, side: int, foot_y: float) -> int:
        """The segment of ``side`` at the foot's height ``foot_y`` [l0]."""
        return int(segment_at(self.sides, side, foot_y))

    def side_x(self, side: int, y: float) -> float:
        """Where ``side`` is at height ``y`` [l0]: its ``x`` [l0]."""
        return float(side_x(self.sides, side, y))

    def next_leg(self, row: int, body: tuple[float, float], velocity: tuple[float, float], side: int,
                 leg: tuple[float, float]) -> Placement:  # fmt: skip
        """After touchdown ``row`` of the plan — the body at ``body`` with ``velocity`` (wall
        coordinates), its foot on ``side``, the leg as realised ``(psi0, zeta0)`` — the leg for the
        plan's touchdown ``row + 1``. Past the plan's end: OFF_PLAN with NaNs."""
        foot_y = body[1] - leg[1] * math.sin(leg[0])
        trial = np.zeros(TRIAL_SIZE)
        trial[X], trial[Y], trial[XDOT], trial[YDOT] = *body, *velocity
        trial[SIDE], trial[SEGMENT], trial[PSI0], trial[ZETA0] = side, self.segment_of(side, foot_y), *leg
        if row + 1 >= len(self.steps):
            return Placement(OK, OFF_PLAN, math.nan, math.nan, 1 - side, -1, (math.nan, math.nan))
        _side, segment, target = self.planned(row + 1)
        status = lift_off_from(trial, self.model, self.sides, np.empty(STATE_SIZE), np.empty((0, STATE_SIZE)))
        if status != OK:
            return Placement(int(status), OFF_PLAN, math.nan, math.nan, 1 - side, segment, target)
        liftoff = trial[LIFT_X : LIFT_YDOT + 1]
        found, psi0, zeta0 = place_from_liftoff(self.model, self.sides, side, *liftoff, self.aims[row + 1],
                                                self.settings)  # fmt: skip
        return Placement(OK, int(found), float(psi0), float(zeta0), 1 - side, segment, target)
