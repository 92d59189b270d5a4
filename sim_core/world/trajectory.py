"""Sampled paths in a world, for plots and the 3D view (docs/model.md §8).

The climb of :mod:`sim_core.world.climb` with its stances sampled between the integrator's own
nodes and its flights in closed form, as :mod:`sim_core.model.trajectory` samples the map's: the
same :class:`~sim_core.model.trajectory.Trajectory` columns, in wall coordinates and ``l0``, the foot
where the world puts it.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_jumps
from sim_core.model.trajectory import (
    DEFAULT_SAMPLE_RATE,
    MAX_STANCE_NODES,
    Trajectory,
    flight_piece,
    joined_columns,
    stance_piece,
)
from sim_core.model.validation import check_range
from sim_core.world.climb import WorldClimb, first_touchdown, section_orbit
from sim_core.world.geometry import LEFT, pack
from sim_core.world.stride import world_jump
from sim_core.world.world import World


def simulate_world_trajectory(
    model: ModelParams,
    world: World,
    schedule: ControlSchedule,
    state,
    jumps: int,
    *,
    foot_y: float = 0.0,
    sample_rate: float = DEFAULT_SAMPLE_RATE,
) -> tuple[Trajectory, WorldClimb]:
    """Climb ``jumps`` jumps in ``world`` from touchdown 0 (as :func:`sim_core.world.climb.climb_world`)
    and sample the path: ``(trajectory, climb)``. The trajectory's ``section_states`` are the
    touchdowns' velocities in the flipped frame (docs/model.md §4) and its ``rises`` the feet's."""
    jumps = check_jumps(jumps)
    check_range("sample_rate", sample_rate, 0.0, 1e6, high_open=False)
    start, segment = first_touchdown(model, world, schedule, state, foot_y)
    sides, parameters = pack(world, model.mu), model.record()
    record = np.empty((MAX_STANCE_NODES, STATE_SIZE))
    states, on_side, on_segment = [start], [LEFT], [segment]
    pieces, touchdown_times, clock, failure = [], [0.0], 0.0, None
    for k in range(jumps):
        pieces_k, status, touchdown, next_side, next_segment, duration = jump_path(
            parameters, sides, states[-1], on_side[-1], on_segment[-1], schedule[k], schedule[k + 1],
            clock, sample_rate, k, record,
        )  # fmt: skip
        pieces.extend(pieces_k)
        if status != OK:
            failure = Failure(status)
            break
        clock += duration
        states.append(touchdown)
        on_side.append(next_side)
        on_segment.append(next_segment)
        touchdown_times.append(clock)
    touchdowns = np.array(states)
    climb = WorldClimb(touchdowns, np.array(on_side), np.array(on_segment), failure,
                       None if failure is None else len(states))  # fmt: skip
    orbit = section_orbit(climb, schedule)  # the touchdowns as the map's section states and rises
    columns = joined_columns(pieces)
    trajectory = Trajectory(
        **columns,
        touchdown_times=np.array(touchdown_times),
        section_states=orbit.states,
        rises=orbit.rises,
        failure=failure,
        failed_jump=climb.failed_jump,
    )
    return trajectory, climb


def jump_path(model, sides, touchdown, side, segment, leg, next_leg, clock, sample_rate, k, record):
    """One jump of a world climb, sampled: from ``touchdown`` (the body's ``x, y, xdot, ydot`` in
    wall coordinates [l0]) on ``side``'s ``segment`` at time ``clock``, with ``leg`` in stance and
    ``next_leg`` flying. Returns ``(pieces, status, next touchdown, next side, next segment,
    duration)``: the :class:`~sim_core.model.trajectory.Trajectory` columns of its stance and flight
    (``k``: its jump index), and where and when the next touchdown is (NaNs after a failure)."""
    x, y, xdot, ydot = touchdown
    mirror = 1.0 if side == LEFT else -1.0
    foot = (mirror * x - leg.zeta0 * math.cos(leg.psi0), y - leg.zeta0 * math.sin(leg.psi0))  # stance frame
    status, *landing, next_side, next_segment, stance_time, flight_time, rows = world_jump(
        x, y, xdot, ydot, side, segment, leg.psi0, leg.zeta0, next_leg.psi0, next_leg.zeta0, model, sides, record
    )
    pieces = []
    if rows >= 2:
        pieces.append(stance_piece(record[:rows], clock, sample_rate, mirror, foot[0], foot[1], k))
    if status != OK:
        return pieces, status, np.array(landing), side, segment, math.nan
    pieces.append(flight_piece(record[rows - 1], clock, flight_time, sample_rate, mirror, *foot, next_leg, k))
    return pieces, status, np.array(landing), next_side, next_segment, stance_time + flight_time
