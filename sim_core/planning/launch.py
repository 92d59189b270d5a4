"""Where a climb starts: the body's velocity at touchdown 0 — the 30:0.9 gait's when none is given,
or, for a robot launched on a leg, that leg's own gait's (docs/worlds.md)."""

from __future__ import annotations

from sim_core.model.controls import ControlSchedule
from sim_core.model.params import ModelParams


def start_velocity(model: ModelParams) -> tuple[float, float]:
    """The body's velocity at touchdown 0 when none is given: the 30:0.9 gait's (docs/worlds.md)."""
    from sim_core.section.gait_search import gait_of

    state = gait_of(model, ControlSchedule.from_degrees([(30.0, 0.9)])).state
    return float(state[0]), float(state[1])


def launch_velocity(model: ModelParams, schedule: ControlSchedule) -> tuple[float, float] | None:
    """The velocity of the gait of ``schedule``'s one leg, found as the virtual robot finds it; None without one."""
    from sim_core.model.errors import FixedPointNotFound
    from sim_core.model.presets import START_GUESS
    from sim_core.section.gait_search import gait_of

    try:
        state = gait_of(model, schedule, guess=START_GUESS).state
    except FixedPointNotFound:
        return None
    return float(state[0]), float(state[1])
