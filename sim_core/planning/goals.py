"""Whether a goal height can be asked of a world (:func:`check_goal`): the planner's and the foothold
study's one check."""

from __future__ import annotations

import math

from sim_core.model.errors import ParameterError
from sim_core.model.validation import check_range
from sim_core.world.world import World


def check_goal(world: World, goal: float, foot_y: float, *, name: str | None = None, metres: float | None = None,
               footholds: bool = True):  # fmt: skip
    """``(goal, foot_y)`` [l0] if a foot can stand at ``goal`` in ``world`` from a start at
    ``foot_y``: above the start, at most the world's top and, with ``footholds``, a world with a
    foothold (a segment with grip) whose top is at ``goal`` or higher; a ParameterError naming the
    field otherwise, in metres where ``metres`` (l0 [m]) is given. ``name``: the world as the
    caller knows it. (The planner asks without ``footholds``: it says how high it got instead.)"""
    goal, foot_y = check_range("goal_height", goal), check_range("foot_y", foot_y)
    name = name or world.name or "the world"
    unit = 1.0 if metres is None else metres

    def said(value: float) -> str:
        return f"{value * unit:.3f} m" if metres is not None else f"{value:g} l0"

    highest = [side.points[1:, 1][~(side.mu == 0.0)] for side in (world.left, world.right)]
    if footholds and not any(tops.size for tops in highest):
        raise ParameterError("world", f"{name} has no foothold: every segment of both sides is without grip")
    if goal <= foot_y:
        raise ParameterError("goal_height", f"must be above the start's foot ({said(foot_y)}), got {said(goal)}")
    if goal > world.top:
        raise ParameterError("goal_height", f"must be at most {name}'s top ({said(world.top)}), got {said(goal)}")
    best = max((float(tops.max()) for tops in highest if tops.size), default=-math.inf)
    if footholds and goal > best:
        raise ParameterError(
            "goal_height", f"must be at most the top of {name}'s highest foothold ({said(best)}), got {said(goal)}"
        )
    return goal, foot_y
