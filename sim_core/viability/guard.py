"""The viability kernel as a controller's safety guard: no command whose next step leaves it.

A law that holds the leg angle at ``psi0`` and chooses zeta0 within a range can only keep the
robot going from the states of *that* action set's kernel, so the guard is computed for it: the
mid-chute section (:mod:`sim_core.viability.step_map`) with ``psi0`` one node and zeta0 over the
law's range. At run time a candidate command is allowed only if the step it starts lands where
the kernel allows (every node around the state reached is in the kernel, as for the grid's own
pairs), so the command is a viable state-action pair of the model the law was designed on.

The guard travels inside the law's parameter array (the compiled loop takes flat float arrays):
``[x nodes, y nodes, xdot axis..., ydot axis..., kernel mask (0/1) in C order...]`` from
``offset``.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.model.failures import OK
from sim_core.model.noisy_map import to_middle
from sim_core.model.params import ModelParams
from sim_core.viability.engine import ViabilityGrid, compute_viability
from sim_core.viability.grid import DEFAULT_XDOT, DEFAULT_YDOT
from sim_core.viability.step_map import section_step_map

GUARD_STATES = 60  # nodes per velocity axis: 0.08-0.15 sqrt(g l0) apart over the default window
GUARD_ACTIONS = 19  # zeta0 nodes over the law's range


def design_guard(
    model: ModelParams,
    psi0_deg: float,
    zeta0_range: tuple[float, float],
    *,
    states: int = GUARD_STATES,
    actions: int = GUARD_ACTIONS,
) -> tuple[float, ...]:
    """The kernel of ``model`` with the leg angle held at ``psi0_deg`` and zeta0 over
    ``zeta0_range``, laid out for :func:`lands_in_kernel`."""
    grid = ViabilityGrid(
        (np.linspace(*DEFAULT_XDOT, states), np.linspace(*DEFAULT_YDOT, states)),
        (np.array([math.radians(psi0_deg)]), np.linspace(*zeta0_range, actions)),
    )
    result = compute_viability(section_step_map(model), grid)
    xdot, ydot = grid.state_axes
    return (float(states), float(states), *xdot.tolist(), *ydot.tolist(), *result.kernel.astype(float).ravel().tolist())


@kernel
def lands_in_kernel(parameters, offset, psi, liftoff_xdot, liftoff_ydot, d_hat):
    """Whether the flight from a lift-off (leg angle ``psi`` [rad], body velocity) reaches the
    middle of the chute inside the guard's kernel: every node around it in the kernel, the
    state within the grid (a landing past it is not known to be viable)."""
    status, xdot, ydot = to_middle(psi, liftoff_xdot, liftoff_ydot, d_hat)
    if status != OK:
        return False
    columns = int(parameters[offset])
    rows = int(parameters[offset + 1])
    x_axis = parameters[offset + 2 : offset + 2 + columns]
    y_axis = parameters[offset + 2 + columns : offset + 2 + columns + rows]
    mask = parameters[offset + 2 + columns + rows :]
    i = np.searchsorted(x_axis, xdot, side="right")  # np.digitize's bin: nodes i - 1 and i around it
    j = np.searchsorted(y_axis, ydot, side="right")
    if not (1 <= i <= columns - 1 and 1 <= j <= rows - 1):
        return False
    for node_x in (i - 1, i):
        for node_y in (j - 1, j):
            if mask[node_x * rows + node_y] == 0.0:
                return False
    return True
