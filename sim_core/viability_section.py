"""The ParkourBot's own step map for the viability engine (:mod:`sim_core.viability`), on the
mid-chute section of :mod:`sim_core.mfpt_kernels`.

The state is the flight's velocity halfway between the walls, ``(xdot, ydot)`` [sqrt(g l0)]
(``xdot > 0``: toward the coming wall), optionally with the pitch the coming leg sees [rad] as a
third dimension; the action is the coming leg's ``(psi0 [rad], zeta0 [l0])``. Halfway between the
walls nothing of the coming jump has been chosen yet, so every action is open to every state
(at a touchdown the leg in stance was chosen one jump earlier). One step flies to the wall,
runs the stance and flies back to the middle; without noise the pitch keeps its size and
changes sign (the next leg stands on the other wall). Heights do not enter: the chute is
unbounded, so viability is about the velocity alone.

:func:`section_grid` lays out the default grid: 60 x 60 states about the paper's gaits and
20 x 20 actions over the robot's range, the 1.44 million pairs the issue's benchmark asks for.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from sim_core._jit import parallel_kernel
from sim_core.failures import OK
from sim_core.integrate import STATE_SIZE
from sim_core.mfpt_kernels import middle_step
from sim_core.params import ModelParams
from sim_core.validation import ParameterError, check_range
from sim_core.viability import StepMap, ViabilityGrid

# Defaults: with the leg free over its range nearly every velocity the paper's gaits fly at (xdot
# about 0.7-1.6, ydot -0.3-1.4) is viable; the paper preset's kernel ends near xdot 4 and
# ydot -5 / +4, so the window reaches past that for its edge to show.
DEFAULT_XDOT = (0.05, 4.5)
DEFAULT_YDOT = (-4.5, 4.5)
DEFAULT_PSI0_DEG = (15.0, 55.0)
DEFAULT_ZETA0 = (0.70, 0.98)
DEFAULT_STATES = 60
DEFAULT_ACTIONS = 20
MAX_PITCH_DEG = 30.0


def section_step_map(model: ModelParams, *, with_pitch: bool = False) -> StepMap:
    """``model``'s noiseless mid-chute map as a step map; states ``(xdot, ydot[, pitch])``, actions
    ``(psi0, zeta0)``."""
    if model.d_hat <= 2.0:
        raise ParameterError("d_hat", f"must exceed 2 for the mid-chute section, got {model.d_hat:g}")
    parameters = model.kernel_args()
    dimensions = 3 if with_pitch else 2

    def step(states: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        states = np.ascontiguousarray(states, dtype=np.float64)
        if states.ndim != 2 or states.shape[1] != dimensions:
            raise ValueError(f"states must be (N, {dimensions}), got {states.shape}")
        reached = np.empty_like(states)
        failed = np.empty(states.shape[0], dtype=bool)
        middle_steps(states, np.ascontiguousarray(actions, dtype=np.float64), *parameters, reached, failed)
        return reached, failed

    return step


@parallel_kernel
def middle_steps(states, actions, alpha, d_hat, c_zeta, c_psi, mu, reached, failed):
    """One noiseless mid-chute step for each row (pitch in column 2 when there is one)."""
    no_record = np.empty((0, STATE_SIZE))
    with_pitch = states.shape[1] == 3
    for i in prange(states.shape[0]):
        pitch = states[i, 2] if with_pitch else 0.0
        status, xdot, ydot = middle_step(
            states[i, 0], states[i, 1], pitch, actions[i, 0], actions[i, 1],
            0.0, 0.0, 0.0, 0.0, alpha, d_hat, c_zeta, c_psi, mu, no_record,
        )  # fmt: skip
        failed[i] = status != OK
        reached[i, 0] = xdot
        reached[i, 1] = ydot
        if with_pitch:
            reached[i, 2] = -pitch


def section_grid(
    *,
    states: int = DEFAULT_STATES,
    actions: int = DEFAULT_ACTIONS,
    xdot_range: tuple[float, float] = DEFAULT_XDOT,
    ydot_range: tuple[float, float] = DEFAULT_YDOT,
    psi0_deg_range: tuple[float, float] = DEFAULT_PSI0_DEG,
    zeta0_range: tuple[float, float] = DEFAULT_ZETA0,
    pitch_nodes: int = 0,
    pitch_deg: float = 0.0,
) -> ViabilityGrid:
    """A grid of ``states`` nodes per velocity axis and ``actions`` per control axis; with
    ``pitch_nodes`` > 0 a third state axis over ``[-pitch_deg, pitch_deg]`` (an odd count puts
    a node at zero; the axis is symmetric, so a pitch's sign change lands on a node)."""
    for field, count in (("states", states), ("actions", actions)):
        if isinstance(count, bool) or int(count) != count or count < 2:
            raise ParameterError(field, f"must be an integer >= 2 nodes per axis, got {count!r}")
    x_low, x_high = _interval("xdot_range", xdot_range, 0.0, 20.0)
    y_low, y_high = _interval("ydot_range", ydot_range, -20.0, 20.0)
    p_low, p_high = _interval("psi0_range", psi0_deg_range, 1.0, 89.0)
    z_low, z_high = _interval("zeta0_range", zeta0_range, 0.05, 0.999)
    state_axes = [np.linspace(x_low, x_high, int(states)), np.linspace(y_low, y_high, int(states))]
    if pitch_nodes:
        if isinstance(pitch_nodes, bool) or int(pitch_nodes) != pitch_nodes or pitch_nodes < 2:
            raise ParameterError("pitch_nodes", f"must be 0 (no pitch axis) or an integer >= 2, got {pitch_nodes!r}")
        limit = check_range("pitch_deg", pitch_deg, 0.0, MAX_PITCH_DEG)
        if limit == 0.0:
            raise ParameterError("pitch_deg", f"must be in (0, {MAX_PITCH_DEG:g}] with a pitch axis, got 0")
        state_axes.append(np.radians(np.linspace(-limit, limit, int(pitch_nodes))))
    action_axes = (np.radians(np.linspace(p_low, p_high, int(actions))), np.linspace(z_low, z_high, int(actions)))
    return ViabilityGrid(tuple(state_axes), action_axes)


def _interval(field: str, interval, low: float, high: float) -> tuple[float, float]:
    try:
        first, second = (check_range(field, value, low, high) for value in interval)
    except (TypeError, ValueError) as error:
        if isinstance(error, ParameterError):
            raise
        raise ParameterError(field, f"must be a pair (low, high), got {interval!r}") from None
    if not first < second:
        raise ParameterError(field, f"must be an interval with low < high within [{low:g}, {high:g}]")
    return first, second


def degrees_of(actions: np.ndarray) -> np.ndarray:
    """Actions ``(psi0 [rad], zeta0)`` with psi0 in degrees, for people."""
    out = np.array(actions, dtype=np.float64, copy=True)
    out[..., 0] = np.degrees(out[..., 0])
    return out
