"""One jump of the Poincaré map and orbits of many jumps, compiled (docs/model.md §2, §4).

A jump starts at the section — touchdown on the left wall, after the coordinate flip — with
section state ``(xdot, ydot)`` (``xdot < 0``: the body flies toward the left wall). It runs
the stance (:func:`sim_core.model.integrate.stance`), the closed-form flight to the right wall, and
flips coordinates so the next touchdown is again on the left wall.

These are kernels: floats, arrays and the model's record (``model``,
:meth:`sim_core.model.params.ModelParams.record`, read by field) in, a status out, no validation
beyond what keeps them from producing garbage. The validated entry point is
:mod:`sim_core.model.poincare`; trajectories and the studies' own compiled loops (basins, MJTF,
the closed loop) call :func:`jump` directly.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.controls import PSI0_COLUMN, ZETA0_COLUMN
from sim_core.model.failures import INVALID_STATE, NO_FLIGHT, OK
from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, TIME, ZETA_DOT, stance


@kernel
def touchdown_polar_state(xdot, ydot, psi0, zeta0):
    """Leg-frame rates at touchdown: ``(zeta_dot, psi_dot)`` from the body velocity (docs/model.md §2)."""
    cos_psi = math.cos(psi0)
    sin_psi = math.sin(psi0)
    zeta_dot = xdot * cos_psi + ydot * sin_psi
    psi_dot = (-xdot * sin_psi + ydot * cos_psi) / zeta0
    return zeta_dot, psi_dot


@kernel
def liftoff_velocity(psi, zeta_dot, psi_dot):
    """Body velocity ``(xdot, ydot)`` at lift-off (``zeta = 1``) from the leg-frame rates (docs/model.md §2)."""
    cos_psi = math.cos(psi)
    sin_psi = math.sin(psi)
    return zeta_dot * cos_psi - psi_dot * sin_psi, zeta_dot * sin_psi + psi_dot * cos_psi


@kernel
def lift_off(xdot, ydot, psi0, zeta0, model, record):
    """A jump's stance alone: from its touchdown (section state ``xdot, ydot``, controls ``psi0
    [rad], zeta0``) to lift-off. Returns ``(status, psi, liftoff_xdot, liftoff_ydot, stance_time,
    rows_recorded)``: the leg angle [rad] and body velocity at lift-off, NaN where the stance
    failed (its time is kept where one was integrated); ``record`` as for :func:`jump`."""
    nan = math.nan
    if not math.isfinite(xdot + ydot + psi0 + zeta0) or xdot >= 0.0:
        return INVALID_STATE, nan, nan, nan, nan, 0
    zeta_dot, psi_dot = touchdown_polar_state(xdot, ydot, psi0, zeta0)
    final = np.empty(STATE_SIZE)
    # The integrator keeps scalar parameters, the four it uses: its DOP853 steps are generated
    # (scripts/generate_dop853.py) and tested on their own (tests/sim_core/model/test_dop853.py).
    status, rows = stance(
        zeta0, psi0, zeta_dot, psi_dot, model.alpha, model.c_zeta, model.c_psi, model.mu, final, record
    )
    if status != OK:
        return status, nan, nan, nan, final[TIME], rows
    psi = final[PSI]
    liftoff_xdot, liftoff_ydot = liftoff_velocity(psi, final[ZETA_DOT], final[PSI_DOT])
    return OK, psi, liftoff_xdot, liftoff_ydot, final[TIME], rows


@kernel
def jump(xdot, ydot, psi0, zeta0, next_psi0, next_zeta0, model, record):
    """One application of the Poincaré map.

    Args:
        xdot, ydot: section state at this jump's touchdown (after the flip) [sqrt(g l0)].
        psi0, zeta0: this jump's leg controls [rad, l0]; they set the touchdown just made.
        next_psi0, next_zeta0: the next jump's controls; they set where this flight ends.
        model: the nondimensional model parameters (:class:`sim_core.model.params.ModelRecord`).
        record: stance nodes, see :func:`sim_core.model.integrate.stance` (shape (0, STATE_SIZE) for none).

    Returns:
        ``(status, next_xdot, next_ydot, rise, stance_time, flight_time, rows_recorded)``.
        ``rise`` is the next foot's height minus this foot's [l0]. On failure the numbers
        after ``status`` are NaN, except the stance time where a stance was integrated.
    """
    nan = math.nan
    if not math.isfinite(next_psi0 + next_zeta0) or not (0.0 < next_zeta0 < 1.0):
        return INVALID_STATE, nan, nan, nan, nan, nan, 0
    status, psi, liftoff_xdot, liftoff_ydot, stance_time, rows = lift_off(xdot, ydot, psi0, zeta0, model, record)
    if status != OK:
        return status, nan, nan, nan, stance_time, nan, rows
    status, next_xdot, next_ydot, touchdown_height, flight_time = flight(
        psi, liftoff_xdot, liftoff_ydot, model.d_hat, next_psi0, next_zeta0
    )
    if status != OK:
        return status, nan, nan, nan, stance_time, nan, rows
    rise = touchdown_height - next_zeta0 * math.sin(next_psi0)
    return OK, next_xdot, next_ydot, rise, stance_time, flight_time, rows


@kernel
def flight(psi, liftoff_xdot, liftoff_ydot, d_hat, next_psi0, next_zeta0):
    """The closed-form flight from lift-off (leg angle ``psi`` [rad], body velocity) to the other
    wall, where the next leg touches down at ``(next_psi0, next_zeta0)``: ``(status, next_xdot,
    next_ydot, touchdown_height, flight_time)``, the state flipped to the left wall and the body's
    height above this foot [l0]; NO_FLIGHT and NaNs where the body never reaches that wall."""
    nan = math.nan
    # From x = -d/2 + cos(psi) to the next touchdown x = d/2 - zeta0' cos(psi0').
    distance = d_hat - math.cos(psi) - next_zeta0 * math.cos(next_psi0)
    if liftoff_xdot <= 0.0 or distance <= 0.0:
        return NO_FLIGHT, nan, nan, nan, nan
    flight_time = distance / liftoff_xdot
    touchdown_height = math.sin(psi) + liftoff_ydot * flight_time - 0.5 * flight_time * flight_time
    # The flip: the right-wall touchdown becomes a left-wall one (x -> -x).
    return OK, -liftoff_xdot, liftoff_ydot - flight_time, touchdown_height, flight_time


@kernel
def scheduled_jump(xdot, ydot, schedule, k, model, no_record):
    """Jump ``k`` of a cyclic schedule (rows ``k`` and ``k + 1`` mod its length); ``no_record`` is
    an empty (0, STATE_SIZE) array, allocated once by the caller's loop.

    Returns ``(status, next_xdot, next_ydot, rise)``.
    """
    period = schedule.shape[0]
    this, following = k % period, (k + 1) % period
    status, xdot, ydot, rise, _, _, _ = jump(
        xdot,
        ydot,
        schedule[this, PSI0_COLUMN],
        schedule[this, ZETA0_COLUMN],
        schedule[following, PSI0_COLUMN],
        schedule[following, ZETA0_COLUMN],
        model,
        no_record,
    )
    return status, xdot, ydot, rise


@kernel
def orbit(xdot, ydot, schedule, first_jump, model, states, rises):
    """Iterate the map ``rises.shape[0]`` times with a cyclic control schedule.

    Args:
        schedule: shape (m, 2), columns psi0 [rad] and zeta0 [l0]; jump k uses row
            ``(first_jump + k) % m``.
        states: output, shape (n + 1, 2): the section states, starting with ``(xdot, ydot)``;
            rows after a failure are NaN.
        rises: output, shape (n,): height gain per jump [l0]; NaN after a failure.

    Returns:
        ``(status, jumps_completed)``; on failure jump ``jumps_completed`` (0-based) failed.
    """
    jumps = rises.shape[0]
    no_record = np.empty((0, STATE_SIZE))
    states[:, :] = math.nan
    rises[:] = math.nan
    states[0, 0] = xdot
    states[0, 1] = ydot
    for k in range(jumps):
        status, xdot, ydot, rise = scheduled_jump(xdot, ydot, schedule, first_jump + k, model, no_record)
        if status != OK:
            return status, k
        states[k + 1, 0] = xdot
        states[k + 1, 1] = ydot
        rises[k] = rise
    return OK, jumps


@parallel_kernel
def orbit_batch(initial, schedules, first_jump, model, states, rises, status, completed):
    """:func:`orbit` for many starts on all cores.

    Args:
        initial: shape (N, 2) section states.
        schedules: shape (S, m, 2); S = 1 shares one schedule, S = N gives each start its own.
        states: output (N, n + 1, 2); rises: output (N, n); status, completed: output (N,) int.
    """
    shared = schedules.shape[0] == 1
    for i in prange(initial.shape[0]):
        schedule = schedules[0] if shared else schedules[i]
        status[i], completed[i] = orbit(initial[i, 0], initial[i, 1], schedule, first_jump, model, states[i], rises[i])
