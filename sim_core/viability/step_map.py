"""The ParkourBot's own step map for the viability engine (:mod:`sim_core.viability.engine`), on the
mid-chute section of :mod:`sim_core.model.noisy_map`.

The state is the flight's velocity halfway between the walls, ``(xdot, ydot)`` [sqrt(g l0)]
(``xdot > 0``: toward the coming wall), optionally with the pitch the coming leg sees [rad] as a
third dimension; the action is the coming leg's ``(psi0 [rad], zeta0 [l0])``. Halfway between the
walls nothing of the coming jump has been chosen yet, so every action is open to every state
(at a touchdown the leg in stance was chosen one jump earlier). One step flies to the wall,
runs the stance and flies back to the middle; without noise the pitch keeps its size and
changes sign (the next leg stands on the other wall). Heights do not enter: the chute is
unbounded, so viability is about the velocity alone.

Its grid, :func:`sim_core.viability.grid.section_grid`, loads no kernels (the CLI's options and
the service's schemas read it).
"""

from __future__ import annotations

import numpy as np
from numba import prange

from sim_core._jit import parallel_kernel
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noisy_map import middle_step
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError
from sim_core.viability.engine import StepMap


def section_step_map(model: ModelParams, *, with_pitch: bool = False) -> StepMap:
    """``model``'s noiseless mid-chute map as a step map; states ``(xdot, ydot[, pitch])``, actions
    ``(psi0, zeta0)``."""
    if model.d_hat <= 2.0:
        raise ParameterError("d_hat", f"must exceed 2 for the mid-chute section, got {model.d_hat:g}")
    parameters = model.record()
    dimensions = 3 if with_pitch else 2

    def step(states: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        states = np.ascontiguousarray(states, dtype=np.float64)
        if states.ndim != 2 or states.shape[1] != dimensions:
            raise ValueError(f"states must be (N, {dimensions}), got {states.shape}")
        reached = np.empty_like(states)
        failed = np.empty(states.shape[0], dtype=bool)
        middle_steps(states, np.ascontiguousarray(actions, dtype=np.float64), parameters, reached, failed)
        return reached, failed

    return step


@parallel_kernel
def middle_steps(states, actions, model, reached, failed):
    """One noiseless mid-chute step for each row (pitch in column 2 when there is one)."""
    no_record = np.empty((0, STATE_SIZE))
    with_pitch = states.shape[1] == 3
    for i in prange(states.shape[0]):
        pitch = states[i, 2] if with_pitch else 0.0
        status, xdot, ydot = middle_step(
            states[i, 0], states[i, 1], pitch, actions[i, 0], actions[i, 1], 0.0, 0.0, 0.0, 0.0, model, no_record
        )
        failed[i] = status != OK
        reached[i, 0] = xdot
        reached[i, 1] = ydot
        if with_pitch:
            reached[i, 2] = -pitch
