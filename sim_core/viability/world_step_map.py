"""Viability in a world (docs/model.md §8): the step map of :mod:`sim_core.world.centre` for the
viability engine (:mod:`sim_core.viability.engine`), and its grid.

The state is the body crossing the chute's centre line: its height ``y`` [l0] and velocity
``(xdot, ydot)`` [sqrt(g l0)], the sign of ``xdot`` naming the side it flies toward; the action
the coming leg's ``(psi0 [rad], zeta0)``. Height matters now: footholds are where they are, and
the floor ends a climb. A state is viable if some action keeps it, jump after jump, on states
that are, or takes it to the world's top — the chute climbed, the step's goal (the engine's
``done``); the engine's conservative rule (every corner of the bin reached viable) holds as on
parallel walls. The world must have its centre line ``x = 0`` inside it at every height.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from sim_core._jit import parallel_kernel
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError, check_interval
from sim_core.viability.engine import StepMap
from sim_core.viability.grid import DEFAULT_PSI0_DEG, DEFAULT_ZETA0, ViabilityGrid, check_node_counts, control_axes
from sim_core.world.centre import centre_step
from sim_core.world.geometry import pack
from sim_core.world.world import World

DEFAULT_XDOT = (-2.5, 2.5)  # [sqrt(g l0)]: both directions; the centre bins never reach a side
DEFAULT_YDOT = (-3.0, 3.0)
# Measured 2026-12-06 with the top as the goal: 12 and 24 heights give kernels within 2.4 points
# of each other (parallel walls 83.1% and 84.3%); without that goal every climb left the grid and
# the kernel hung on the height grid (12 heights: none).
DEFAULT_HEIGHTS, DEFAULT_STATES, DEFAULT_ACTIONS = 12, 48, 12


def world_step_map(model: ModelParams, world: World) -> StepMap:
    """``model``'s noiseless centre-line map in ``world``; states ``(y, xdot, ydot)``, actions
    ``(psi0, zeta0)``."""
    heights = np.concatenate([world.left.points[:, 1], world.right.points[:, 1]])
    if not ((world.left.points[:, 0] < 0).all() and (world.right.points[:, 0] > 0).all()):
        raise ParameterError("world", f"{world.name or 'the world'} must have its centre line x = 0 between its sides "
                             f"at every height (heights {heights.min():g} to {heights.max():g} l0)")  # fmt: skip
    parameters, sides, top = model.record(), pack(world, model.mu), world.top

    def step(states: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        states = np.ascontiguousarray(states, dtype=np.float64)
        if states.ndim != 2 or states.shape[1] != 3:
            raise ValueError(f"states must be (N, 3), got {states.shape}")
        reached = np.empty_like(states)
        failed = np.empty(states.shape[0], dtype=bool)
        centre_steps(states, np.ascontiguousarray(actions, dtype=np.float64), parameters, sides, reached, failed)
        return reached, failed, ~failed & (reached[:, 0] >= top)  # at the top: the chute is climbed

    return step


def world_grid(
    world: World,
    *,
    heights: int = DEFAULT_HEIGHTS,
    states: int = DEFAULT_STATES,
    actions: int = DEFAULT_ACTIONS,
    xdot_range: tuple[float, float] = DEFAULT_XDOT,
    ydot_range: tuple[float, float] = DEFAULT_YDOT,
    psi0_deg_range: tuple[float, float] = DEFAULT_PSI0_DEG,
    zeta0_range: tuple[float, float] = DEFAULT_ZETA0,
) -> ViabilityGrid:
    """``heights`` nodes from the floor to the world's top, ``states`` per velocity axis and
    ``actions`` per control axis."""
    check_node_counts(heights=heights, states=states, actions=actions)
    x_low, x_high = check_interval("xdot_range", xdot_range, -20.0, 20.0)
    y_low, y_high = check_interval("ydot_range", ydot_range, -20.0, 20.0)
    state_axes = (np.linspace(0.0, world.top, int(heights)), np.linspace(x_low, x_high, int(states)),
                  np.linspace(y_low, y_high, int(states)))  # fmt: skip
    return ViabilityGrid(state_axes, control_axes(actions, psi0_deg_range, zeta0_range))


@parallel_kernel
def centre_steps(states, actions, model, sides, reached, failed):
    """One noiseless centre-line step for each row."""
    no_record = np.empty((0, STATE_SIZE))
    for i in prange(states.shape[0]):
        status, y, xdot, ydot = centre_step(
            states[i, 0], states[i, 1], states[i, 2], actions[i, 0], actions[i, 1], model, sides, no_record
        )
        failed[i] = status != OK
        reached[i, 0], reached[i, 1], reached[i, 2] = y, xdot, ydot
