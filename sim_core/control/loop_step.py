"""One jump of a closed loop from its whole state: the one step the controller study's trials and
the splitting estimate of a loop's MFPT (:mod:`sim_core.robustness.splitting`) both take.

The loop's state at touchdown ``k``, before the law acts, is a flat float array
(:data:`LOOP_STATE_SIZE`): the section state ``xdot, ydot`` [sqrt(g l0)], the controls the foot
touched down with ``psi0`` [rad] and ``zeta0`` [l0] (noise and pitch included), the foot's height
[l0], the pitch [rad] and the law's memory (:data:`sim_core.control.laws.MEMORY_SIZE` floats).
With the parity of ``k`` (which wall) it is everything the next jump depends on, so a run can be
stopped, copied and continued with fresh noise: what splitting needs. The noise is drawn in the
order of :mod:`sim_core.model.noise_rules`, from numba's generator as the caller seeded it.

A loop holds a height in a chute with a floor: a run whose body comes down below it (where the
climb's first foot touched) has lost its height, and ends there as :data:`~sim_core.model.failures.FLOOR`,
as the climb sequencer's (:mod:`sim_core.climb.sequencer`) and the robot's runs end. Without it a falling
run counts as holding until its speed breaks a jump, hundreds of jumps later.
"""

from __future__ import annotations

import math

from sim_core._jit import kernel
from sim_core.control.controllers import control_step, start_memory
from sim_core.control.laws import MEMORY_SIZE
from sim_core.model.failures import FLOOR, FLOOR_HEIGHT, OK
from sim_core.model.noise_rules import commanded_controls, disturbed_state, pitch_step
from sim_core.model.stride import jump

XDOT, YDOT, PSI0, ZETA0, FOOT, PITCH, MEMORY = range(7)
LOOP_STATE_SIZE = MEMORY + MEMORY_SIZE


@kernel
def start_loop(state, kind, xdot, ydot, first_psi0, first_zeta0, noise):
    """Fill ``state`` with the loop at its first touchdown: the foot at height 0, zero pitch, the
    first leg commanded ``(first_psi0, first_zeta0)`` and realised with fresh noise (``noise``: a
    :class:`sim_core.model.noise.NoiseRecord`)."""
    psi0, zeta0 = commanded_controls(0, 0.0, first_psi0, first_zeta0, noise)
    state[XDOT], state[YDOT], state[PSI0], state[ZETA0] = xdot, ydot, psi0, zeta0
    state[FOOT], state[PITCH] = 0.0, 0.0
    state[MEMORY:] = start_memory(kind, first_psi0, first_zeta0)


@kernel
def body_height(state):
    """The body's height at the touchdown [l0]."""
    return state[FOOT] + state[ZETA0] * math.sin(state[PSI0])


@kernel
def loop_jump(state, k, kind, parameters, noise, model, no_record):
    """From touchdown ``k`` to ``k + 1``: the law reads what touchdown ``k`` shows (its height, the
    pitch tracked in its stance, its section state) and sets touchdown ``k + 1``; ``state`` is
    advanced in place; ``noise`` and ``model`` are the records of :class:`sim_core.model.noise.NoiseModel`
    and :class:`sim_core.model.params.ModelParams`. Returns ``(status, clipped)``: on a jump's failure
    only the law's memory has moved; a touchdown with the body below the floor is reached, and ends
    the run as ``FLOOR``."""
    command_psi0, command_zeta0, clipped = control_step(
        kind, parameters, state[MEMORY:], body_height(state), state[PITCH], state[XDOT], state[YDOT], (k + 1) % 2 == 0
    )
    next_pitch = pitch_step(state[PITCH], noise)
    next_psi0, next_zeta0 = commanded_controls(k + 1, next_pitch, command_psi0, command_zeta0, noise)
    status, xdot, ydot, rise, _stance_time, _flight_time, _ = jump(
        state[XDOT], state[YDOT], state[PSI0], state[ZETA0], next_psi0, next_zeta0, model, no_record
    )
    if status != OK:
        return status, clipped
    xdot, ydot = disturbed_state(xdot, ydot, noise)
    state[XDOT], state[YDOT], state[PSI0], state[ZETA0] = xdot, ydot, next_psi0, next_zeta0
    state[FOOT] += rise
    state[PITCH] = next_pitch
    if body_height(state) < FLOOR_HEIGHT:
        return FLOOR, clipped
    return OK, clipped
