"""One jump between a world's sides and climbs of many jumps, compiled (docs/model.md §8).

A world has no symmetry in ``y``, so the state is taken at touchdown in wall coordinates: the
body's ``(x, y, xdot, ydot)`` [l0, sqrt(g l0)], the side (0 left, 1 right, as
:mod:`sim_core.world.geometry`) and the segment the foot is on. A jump runs the stance about the
foot in the side's stance frame (the flipped frame of §2: the stance side is the left one) with
the friction cone of the foot's segment, lifts off, and flies until the coming leg's foot first
reaches the other side — a quadratic per segment (:func:`sim_core.world.geometry.first_crossing`).

On parallel walls every number is the Poincaré map's (:mod:`sim_core.model.stride`) to rounding:
tests/sim_core/world/test_stride.py checks it to 1e-10.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.controls import PSI0_COLUMN, ZETA0_COLUMN
from sim_core.model.failures import INVALID_STATE, NO_FLIGHT, NO_TOUCHDOWN, OK
from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, TIME, ZETA_DOT, stance_in_cone
from sim_core.model.stride import liftoff_velocity, touchdown_polar_state
from sim_core.world.geometry import FLIGHT_TIME_CAP, first_crossing, side_x

# Columns of a touchdown state
X, Y, XDOT, YDOT = 0, 1, 2, 3
TOUCHDOWN_SIZE = 4


@kernel
def world_jump(x, y, xdot, ydot, side, segment, psi0, zeta0, next_psi0, next_zeta0, model, sides, record):
    """One jump from a touchdown on ``side``'s ``segment`` to the next on the other side.

    Args:
        x, y, xdot, ydot: the body at this touchdown, wall coordinates [l0, sqrt(g l0)]; it
            flies toward ``side`` (``xdot < 0`` on the left side, ``> 0`` on the right).
        side, segment: where the foot is (:mod:`sim_core.world.geometry`'s numbering).
        psi0, zeta0: this leg's controls [rad, l0], set in the body frame (from the horizontal).
        next_psi0, next_zeta0: the next leg's; they set where this flight ends.
        model: :class:`sim_core.model.params.ModelRecord`; sides: :class:`~sim_core.world.geometry.SideArrays`.
        record: stance nodes as :func:`sim_core.model.integrate.stance` (shape (0, STATE_SIZE): none).

    Returns:
        ``(status, x, y, xdot, ydot, side, segment, stance_time, flight_time, rows)`` of the next
        touchdown; on failure NaNs after ``status`` (the stance time kept where one was run),
        this side and segment.
    """
    nan = math.nan
    if not (math.isfinite(next_psi0 + next_zeta0) and 0.0 < next_zeta0 < 1.0):
        return INVALID_STATE, nan, nan, nan, nan, side, segment, nan, nan, 0
    mirror = 1.0 if side == 0 else -1.0  # the side's stance frame: x -> mirror * x
    body_x, body_vx = mirror * x, mirror * xdot
    if not math.isfinite(body_x + y + body_vx + ydot + psi0 + zeta0) or body_vx >= 0.0:
        return INVALID_STATE, nan, nan, nan, nan, side, segment, nan, nan, 0
    foot_x = body_x - zeta0 * math.cos(psi0)
    foot_y = y - zeta0 * math.sin(psi0)
    final = np.empty(STATE_SIZE)
    status, rows = foothold_stance(body_vx, ydot, psi0, zeta0, model, sides, side, segment, final, record)
    stance_time = final[TIME]
    if status != OK:
        return status, nan, nan, nan, nan, side, segment, stance_time, nan, rows
    psi = final[PSI]
    vx, vy = liftoff_velocity(psi, final[ZETA_DOT], final[PSI_DOT])
    hip_x, hip_y = mirror * (foot_x + math.cos(psi)), foot_y + math.sin(psi)
    status, x, y, xdot, ydot, landing, flight_time = world_flight(
        hip_x, hip_y, mirror * vx, vy, side, next_psi0, next_zeta0, sides
    )
    if status != OK:
        return status, nan, nan, nan, nan, side, segment, stance_time, nan, rows
    return OK, x, y, xdot, ydot, 1 - side, landing, stance_time, flight_time, rows


@kernel
def world_flight(x, y, xdot, ydot, side, next_psi0, next_zeta0, sides):
    """The flight from a lift-off off ``side`` (the body at ``x, y`` with velocity ``xdot, ydot``,
    wall coordinates) until the next leg's foot, held at ``(next_psi0, next_zeta0)`` toward the other
    side, first reaches it: ``(status, x, y, xdot, ydot, segment, flight_time)`` of that touchdown
    (:data:`NO_FLIGHT`: the foot starts past the other side or the body flies back;
    :data:`NO_TOUCHDOWN`: no side within the flight's cap; NaNs then)."""
    nan = math.nan
    mirror = 1.0 if side == 0 else -1.0
    vx = mirror * xdot
    next_x = mirror * x + next_zeta0 * math.cos(next_psi0)  # the next leg's foot, in the stance frame
    next_y = y - next_zeta0 * math.sin(next_psi0)
    other = 1 - side
    if vx <= 0.0 or next_x >= mirror * side_x(sides, other, next_y):
        return NO_FLIGHT, nan, nan, nan, nan, -2, nan
    flight_time, landing = first_crossing(sides, other, mirror, next_x, next_y, vx, ydot)
    if not flight_time <= FLIGHT_TIME_CAP:
        return NO_TOUCHDOWN, nan, nan, nan, nan, -2, nan
    touch_x = next_x + vx * flight_time - next_zeta0 * math.cos(next_psi0)
    touch_y = next_y + (ydot - 0.5 * flight_time) * flight_time + next_zeta0 * math.sin(next_psi0)
    return OK, mirror * touch_x, touch_y, xdot, ydot - flight_time, landing, flight_time


@kernel
def foothold_stance(vx, vy, psi0, zeta0, model, sides, side, segment, final, record):
    """The stance on ``side``'s ``segment`` from a touchdown with body velocity ``(vx, vy)`` in the
    side's stance frame, the leg at ``(psi0, zeta0)``, in the foothold's friction cone about its
    inward normal (docs/model.md §8): ``(status, rows)`` as :func:`sim_core.model.integrate.stance`."""
    beta = sides.beta[side, segment + 1]
    half_angle = math.atan(sides.friction[side, segment + 1])
    zeta_dot, psi_dot = touchdown_polar_state(vx, vy, psi0, zeta0)
    return stance_in_cone(
        zeta0, psi0, zeta_dot, psi_dot, model.alpha, model.c_zeta, model.c_psi,
        beta - half_angle, beta + half_angle, final, record,
    )  # fmt: skip


@kernel
def scheduled_world_jump(state, side, segment, schedule, k, model, sides, no_record):
    """Jump ``k`` of a cyclic schedule from ``state`` (a row ``x, y, xdot, ydot``): rows ``k`` and
    ``k + 1`` mod its length. Returns ``(status, x, y, xdot, ydot, side, segment)``."""
    period = schedule.shape[0]
    this, following = k % period, (k + 1) % period
    status, x, y, xdot, ydot, side, segment, _, _, _ = world_jump(
        state[X], state[Y], state[XDOT], state[YDOT], side, segment,
        schedule[this, PSI0_COLUMN], schedule[this, ZETA0_COLUMN],
        schedule[following, PSI0_COLUMN], schedule[following, ZETA0_COLUMN],
        model, sides, no_record,
    )  # fmt: skip
    return status, x, y, xdot, ydot, side, segment


@kernel
def world_orbit(schedule, first_jump, model, sides, states, on_side, on_segment):
    """Climb from the touchdown in ``states[0]``, ``on_side[0]``, ``on_segment[0]`` for
    ``states.shape[0] - 1`` jumps; jump ``k`` uses schedule row ``(first_jump + k) % m``.

    Rows after a failure are NaN (side and segment -1). Returns ``(status, jumps_completed)``;
    on failure jump ``jumps_completed`` (0-based) failed.
    """
    jumps = states.shape[0] - 1
    no_record = np.empty((0, STATE_SIZE))
    states[1:, :] = math.nan
    on_side[1:] = -1
    on_segment[1:] = -1
    side, segment = on_side[0], on_segment[0]
    for k in range(jumps):
        status, x, y, xdot, ydot, side, segment = scheduled_world_jump(
            states[k], side, segment, schedule, first_jump + k, model, sides, no_record
        )
        if status != OK:
            return status, k
        states[k + 1, X], states[k + 1, Y], states[k + 1, XDOT], states[k + 1, YDOT] = x, y, xdot, ydot
        on_side[k + 1], on_segment[k + 1] = side, segment
    return OK, jumps


@parallel_kernel
def world_orbit_batch(schedules, first_jump, model, sides, states, on_side, on_segment, status, completed):
    """:func:`world_orbit` for many starts on all cores: ``states`` (N, n + 1, 4) with each
    start in row 0, ``on_side``/``on_segment`` (N, n + 1), ``schedules`` (S, m, 2) with S = 1
    shared or S = N one each; ``status``, ``completed``: output (N,)."""
    shared = schedules.shape[0] == 1
    for i in prange(states.shape[0]):
        schedule = schedules[0] if shared else schedules[i]
        status[i], completed[i] = world_orbit(schedule, first_jump, model, sides, states[i], on_side[i], on_segment[i])
