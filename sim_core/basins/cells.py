"""The basin test of each cell (docs/model.md §4): the compiled kernels, and undecided cells
continued in rounds up to a jump limit.

A cell's run ends when its orbit comes within ``tolerance`` of the gait's orbit (converged), a
jump fails, or the cap runs out (undecided). With a ``jump_limit`` above the first cap, the
cells still undecided are run on from the state they stopped at, the cap doubled each round
(``max_jumps``, ``2 max_jumps``, … ``jump_limit``), until none is undecided or the limit is
reached. Jump ``k`` of a continued run uses the schedule's phase ``k mod m`` as an uninterrupted
run would, so a cell decides exactly as one run with ``max_jumps = jump_limit`` would; the rounds
only keep the cores busy on the cells that still need them.

A run faster than :data:`FALLING_SPEED` is *falling*: the map has no floor, so a body dropping
down the chute never fails and never converges, and would run to any limit (at zeta0 0.94 every
cell still undecided after 300 jumps had passed 100 sqrt(g l0) within 86 jumps, and ended near
10^8). Such a run stops there, undecided, and is not continued; :attr:`sim_core.basins.basin.Basin.falling`
counts them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_jumps
from sim_core.model.stride import scheduled_jump
from sim_core.model.validation import ParameterError

NOT_CONVERGED = -1  # jumps_to_converge of a cell that never reached the gait
FALLING_SPEED = 100.0  # [sqrt(g l0)]: 50x the fastest gait's section speed; past it a run is falling


def check_jump_limit(jump_limit: int | None, max_jumps: int) -> int:
    """Validate the jump limit (None: ``max_jumps``, no continuation); returns it."""
    if jump_limit is None:
        return max_jumps
    limit = check_jumps(jump_limit, "jump_limit")
    if limit < max_jumps:
        raise ParameterError("jump_limit", f"must be at least the first cap, jumps = {max_jumps}, got {limit}")
    return limit


def caps(max_jumps: int, jump_limit: int) -> list[int]:
    """The caps of the rounds: ``max_jumps``, doubled each round, ending at ``jump_limit``."""
    out = [max_jumps]
    while out[-1] < jump_limit:
        out.append(min(max(2 * out[-1], 1), jump_limit))
    return out


def converge_states(
    model: ModelParams,
    schedule: ControlSchedule,
    orbit: np.ndarray,
    starts: np.ndarray,
    max_jumps: int,
    tolerance: float,
    jump_limit: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The basin test for each row of ``starts`` (N, 2) on all cores: one chunk of a basin.

    ``jump_limit`` (None: ``max_jumps``) continues the undecided cells in rounds (module docstring).

    Returns ``(jumps_to_converge, failure status, jumps simulated)``, int arrays of shape (N,), and
    the section state each run stopped at, shape (N, 2) [sqrt(g l0)] (a failed run: the state
    before the failing jump).
    """
    jump_limit = check_jump_limit(jump_limit, max_jumps)
    states = np.array(starts, dtype=np.float64)  # a copy: each round moves the states on
    count = states.shape[0]
    jumps_to_converge, failure, jumps_done = (np.empty(count, dtype=np.int64) for _ in range(3))
    arguments = (schedule.as_array(), np.ascontiguousarray(orbit, dtype=np.float64), tolerance, model.record())
    cells, first_jump = np.arange(count), 0
    for round_, cap in enumerate(caps(max_jumps, jump_limit)):
        if round_:
            undecided = (jumps_to_converge == NOT_CONVERGED) & (failure == OK)
            cells = np.flatnonzero(undecided & ~is_falling(states))
            if not cells.size:
                break
        part = states[cells]
        outputs = tuple(np.empty(cells.size, dtype=np.int64) for _ in range(3))
        converge_batch(part, first_jump, cap, *arguments, *outputs)
        states[cells] = part
        jumps_to_converge[cells], failure[cells], jumps_done[cells] = outputs
        first_jump = cap
    return jumps_to_converge, failure, jumps_done, states


def is_falling(states: np.ndarray) -> np.ndarray:
    """Whether each section state (rows of ``(xdot, ydot)``) is past :data:`FALLING_SPEED`."""
    return np.hypot(states[..., 0], states[..., 1]) > FALLING_SPEED


@kernel
def _near_orbit(xdot, ydot, phase, period, orbit, tolerance):
    """Whether ``(xdot, ydot)`` at schedule phase ``phase`` lies within ``tolerance`` of the orbit."""
    for j in range(phase, orbit.shape[0], period):
        if math.hypot(xdot - orbit[j, 0], ydot - orbit[j, 1]) < tolerance:
            return True
    return False


@kernel
def converge(xdot, ydot, first_jump, cap, schedule, orbit, tolerance, model):
    """Run jumps ``first_jump`` … ``cap - 1`` from ``(xdot, ydot)``, the state after ``first_jump``
    jumps (already tested when ``first_jump > 0``), until it reaches ``orbit`` or fails.

    Returns ``(jumps_to_converge or NOT_CONVERGED, status, jumps simulated in all, xdot, ydot)``,
    the last two the state it stopped at; a falling run stops undecided as soon as it falls.
    """
    period = schedule.shape[0]
    no_record = np.empty((0, STATE_SIZE))
    if first_jump == 0 and _near_orbit(xdot, ydot, 0, period, orbit, tolerance):
        return 0, OK, 0, xdot, ydot
    for k in range(first_jump, cap):
        status, next_xdot, next_ydot, _ = scheduled_jump(xdot, ydot, schedule, k, model, no_record)
        if status != OK:
            return NOT_CONVERGED, status, k + 1, xdot, ydot
        xdot, ydot = next_xdot, next_ydot
        if _near_orbit(xdot, ydot, (k + 1) % period, period, orbit, tolerance):
            return k + 1, OK, k + 1, xdot, ydot
        if xdot * xdot + ydot * ydot > FALLING_SPEED * FALLING_SPEED:  # falling: it will not decide
            return NOT_CONVERGED, OK, k + 1, xdot, ydot
    return NOT_CONVERGED, OK, cap, xdot, ydot


@parallel_kernel
def converge_batch(
    states,
    first_jump,
    cap,
    schedule,
    orbit,
    tolerance,
    model,
    jumps_to_converge,
    failure,
    jumps,
):
    """:func:`converge` for each row of ``states`` (N, 2) on all cores, each row moved on to where
    its run stopped; outputs are (N,) int arrays."""
    for i in prange(states.shape[0]):
        jumps_to_converge[i], failure[i], jumps[i], states[i, 0], states[i, 1] = converge(
            states[i, 0], states[i, 1], first_jump, cap, schedule, orbit, tolerance, model
        )
