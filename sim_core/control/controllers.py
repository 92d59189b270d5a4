"""Controllers closed once per jump: what is observed at a touchdown sets the next jump's controls.

One interface for every law (docs/model.md §5.2): at touchdown ``k`` the robot observes its body
height and its pitch (the tracker's, §6); the law returns the leg angle and leg length of
touchdown ``k + 1`` (one jump of delay, as on the robot), within the leg's range relative to the
body, and says whether it had to clip them (saturation is counted, not hidden). A controller is
a frozen dataclass (a module of :mod:`sim_core.control.laws`, the registry: its parameters,
checked) that gives the compiled loop a kind (its ``NUMBER``) and a flat parameter array;
:func:`control_step` is the one compiled dispatch, a branch per law.

Kinds so far:

- ``pid``: today's PID on the touchdown height (:func:`sim_core.control.closed_loop.pid_step`), the leg
  angle held at its nominal value.
- ``pid-pitch``: the same PID, and the tracked pitch fed to the leg angle: the next leg, on the
  left wall turned by ``+pitch`` and on the right by ``-pitch`` (§5.1), is commanded ``psi0 ∓
  pitch`` so that it meets the wall at the nominal angle but for one jump's pitch drift. Without
  it the pitch's random walk turns the legs further every jump, the failures of long noisy runs.
- ``lqr``: both leg controls from the section state, the height error and the controls just
  touched down with (:mod:`sim_core.control.return_map_lqr` designs it), the pitch fed back as above.
  The law also sees the section state ``xdot, ydot`` at the touchdown, which the robot's tracker
  estimates from the body's track.
- ``deadbeat``: zeta0 chosen two jumps ahead on the design model's own map from the section state
  (:mod:`sim_core.control.deadbeat`), climbing at most ``climb_per_jump`` a jump, behind a guard that
  never sends a command the model predicts fails; the leg angle nominal, pitch fed back.
- ``placement``: the foot-placement law between parallel walls — the deadbeat's horizon over both
  legs (the angle a step either side of the gait's too), the feet's heights weighed above the
  state; pitch fed back.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.control.closed_loop import pid_step
from sim_core.control.deadbeat import PITCH_GAIN, PSI0_HIGH, PSI0_LOW, deadbeat_leg
from sim_core.control.laws import DEADBEAT, LQR, MEMORY_SIZE, PID_PITCH, PLACEMENT


def new_memory(kind: int, first_psi0: float, first_zeta0: float) -> np.ndarray:
    """A law's state before the first touchdown (:data:`MEMORY_SIZE` floats), whose controls are
    ``(first_psi0 [rad], first_zeta0)``."""
    return start_memory(kind, first_psi0, first_zeta0)


@kernel
def start_memory(kind, first_psi0, first_zeta0):
    memory = np.empty(MEMORY_SIZE)
    if kind in (LQR, DEADBEAT, PLACEMENT):  # the controls of the touchdown before the first command
        memory[0], memory[1] = first_psi0, first_zeta0
    else:  # the PID: no integral, no error before
        memory[0], memory[1] = 0.0, math.nan
    return memory


@kernel
def control_step(kind, parameters, memory, height, pitch, xdot, ydot, next_on_left):
    """The next touchdown's ``(psi0 [rad], zeta0, saturated)`` from what touchdown ``k`` shows: the
    body ``height`` [l0], the ``pitch`` tracked in its stance [rad] and its section state ``xdot,
    ydot``; ``next_on_left``: touchdown ``k + 1`` is on the left wall. ``memory``
    (:func:`new_memory`) is updated in place."""
    if kind == LQR:
        return _lqr_step(parameters, memory, height, pitch, xdot, ydot, next_on_left)
    if kind in (DEADBEAT, PLACEMENT):
        return _deadbeat_step(parameters, memory, height, pitch, xdot, ydot, next_on_left)
    zeta0_min, zeta0_max, psi0 = parameters[5], parameters[6], parameters[7]
    error = parameters[0] - height
    zeta0, integral = pid_step(
        error, memory[1], memory[0], parameters[1], parameters[2], parameters[3], parameters[4], zeta0_min, zeta0_max
    )
    memory[0], memory[1] = integral, error
    saturated = zeta0 <= zeta0_min or zeta0 >= zeta0_max
    if kind == PID_PITCH:
        psi0, clipped = _turned_back(psi0, pitch, next_on_left, parameters[10], parameters[8], parameters[9])
        saturated = saturated or clipped
    return psi0, zeta0, saturated


@kernel
def _lqr_step(parameters, memory, height, pitch, xdot, ydot, next_on_left):
    """``u_next = u* - K x``, x = (section state - the gait's, clipped height error, last command
    - u*); the last command is the memory."""
    psi0_star, zeta0_star, clip = parameters[1], parameters[2], parameters[9]
    error = min(max(height - parameters[0], -clip), clip)
    state_clip = parameters[21]
    xdot_delta = min(max(xdot - parameters[3], -state_clip), state_clip)
    ydot_delta = min(max(ydot - parameters[4], -state_clip), state_clip)
    x = (xdot_delta, ydot_delta, error, memory[0] - psi0_star, memory[1] - zeta0_star)
    psi0_delta, zeta0_delta = 0.0, 0.0
    for j in range(5):
        psi0_delta -= parameters[11 + j] * x[j]
        zeta0_delta -= parameters[16 + j] * x[j]
    zeta0 = min(max(zeta0_star + zeta0_delta, parameters[5]), parameters[6])
    psi0 = min(max(psi0_star + psi0_delta, parameters[7]), parameters[8])
    saturated = zeta0 != zeta0_star + zeta0_delta or psi0 != psi0_star + psi0_delta
    memory[0], memory[1] = psi0, zeta0
    psi0, clipped = _turned_back(psi0, pitch, next_on_left, parameters[10], parameters[7], parameters[8])
    return psi0, zeta0, saturated or clipped


@kernel
def _turned_back(psi0, pitch, next_on_left, pitch_gain, psi0_min, psi0_max):
    """``psi0`` turned back by the tracked pitch the next leg's wall adds (``+pitch`` on the left,
    ``-pitch`` on the right), within the leg's range: ``(psi0, clipped)``. NaN: no pitch tracked."""
    if math.isnan(pitch):
        return psi0, False
    turned = psi0 - pitch_gain * (pitch if next_on_left else -pitch)
    clamped = min(max(turned, psi0_min), psi0_max)
    return clamped, clamped != turned


@kernel
def _deadbeat_step(parameters, memory, height, pitch, xdot, ydot, next_on_left):
    """The leg by :func:`sim_core.control.deadbeat.deadbeat_leg` from the controls last touched down
    with (the memory; the angle before its pitch turn), the angle turned back by the pitch."""
    psi0, zeta0, guarded = deadbeat_leg(parameters, memory[0], memory[1], height, xdot, ydot)
    memory[0], memory[1] = psi0, zeta0
    psi0, clipped = _turned_back(
        psi0, pitch, next_on_left, parameters[PITCH_GAIN], parameters[PSI0_LOW], parameters[PSI0_HIGH]
    )
    return psi0, zeta0, guarded or clipped
