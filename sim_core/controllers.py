"""Controllers closed once per jump: what is observed at a touchdown sets the next jump's controls.

One interface for every law (docs/model.md §5.2): at touchdown ``k`` the robot observes its body
height and its pitch (the tracker's, §6); the law returns the leg angle and leg length of
touchdown ``k + 1`` (one jump of delay, as on the robot), within the leg's range relative to the
body, and says whether it had to clip them (saturation is counted, not hidden). A controller is
a frozen dataclass (:mod:`sim_core.control_laws`: its parameters, checked) that gives the
compiled loop a kind and a flat parameter array; :func:`control_step` is the one compiled dispatch.

Kinds so far:

- ``pid``: today's PID on the touchdown height (:func:`sim_core.closed_loop.pid_step`), the leg
  angle held at its nominal value.
- ``pid-pitch``: the same PID, and the tracked pitch fed to the leg angle: the next leg, on the
  left wall turned by ``+pitch`` and on the right by ``-pitch`` (§5.1), is commanded ``psi0 ∓
  pitch`` so that it meets the wall at the nominal angle but for one jump's pitch drift. Without
  it the pitch's random walk turns the legs further every jump, the failures of long noisy runs.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.closed_loop import pid_step
from sim_core.control_laws import PID_PITCH


def new_memory() -> np.ndarray:
    """A law's state before the first touchdown (:data:`MEMORY_SIZE` floats)."""
    return np.array([0.0, math.nan])


@kernel
def control_step(kind, parameters, memory, height, pitch, next_on_left):
    """The next touchdown's ``(psi0 [rad], zeta0, saturated)`` from touchdown ``k``'s body
    ``height`` [l0] and tracked ``pitch`` [rad]; ``next_on_left``: touchdown ``k + 1`` is on the
    left wall. ``memory`` (:func:`new_memory`) is updated in place."""
    zeta0_min, zeta0_max, psi0 = parameters[5], parameters[6], parameters[7]
    error = parameters[0] - height
    zeta0, integral = pid_step(
        error, memory[1], memory[0], parameters[1], parameters[2], parameters[3], parameters[4], zeta0_min, zeta0_max
    )
    memory[0], memory[1] = integral, error
    saturated = zeta0 <= zeta0_min or zeta0 >= zeta0_max
    if kind == PID_PITCH and not math.isnan(pitch):
        turned = psi0 - parameters[10] * (pitch if next_on_left else -pitch)
        psi0 = min(max(turned, parameters[8]), parameters[9])
        saturated = saturated or psi0 != turned
    return psi0, zeta0, saturated
