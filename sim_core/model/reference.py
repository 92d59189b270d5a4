"""A scipy ``solve_ivp`` implementation of one jump: the benchmark's baseline.

The one deliberate twin of :mod:`sim_core.model.integrate` / :mod:`sim_core.model.stride` (style.md §4):
the same polar equations integrated by scipy's DOP853 with its own event location, in plain
Python. ``parkour bench`` times the compiled kernel against it and reports their largest
difference. (The tests check the kernel against a third, Cartesian, formulation.)
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from sim_core.model.controls import LegControl
from sim_core.model.failures import COLLAPSE, NO_FLIGHT, NO_LIFTOFF, OK, SLIP
from sim_core.model.integrate import COLLAPSE_ZETA, STANCE_TIME_CAP
from sim_core.model.params import ModelParams


def reference_jump(
    model: ModelParams,
    state,
    leg: LegControl,
    next_leg: LegControl,
    *,
    rtol: float = 1e-10,
    atol: float = 1e-10,
) -> tuple[int, float, float, float]:
    """One jump with scipy: ``(status, next_xdot, next_ydot, rise)`` (NaNs on failure)."""
    xdot, ydot = state
    alpha, c_zeta, c_psi = model.alpha, model.c_zeta, model.c_psi  # locals: the equations read them every call
    cos0, sin0 = math.cos(leg.psi0), math.sin(leg.psi0)
    start = [leg.zeta0, leg.psi0, xdot * cos0 + ydot * sin0, (-xdot * sin0 + ydot * cos0) / leg.zeta0]

    def equations(_t, y):
        zeta, psi, zeta_dot, psi_dot = y
        return [
            zeta_dot,
            psi_dot,
            alpha * (1.0 - zeta) + zeta * psi_dot**2 - math.sin(psi) - c_zeta * zeta_dot,
            -(math.cos(psi) + 2.0 * zeta_dot * psi_dot) / zeta - c_psi * psi_dot,
        ]

    psi_limit = math.atan(model.mu)
    events = [
        _terminal(lambda _t, y: y[0] - 1.0, direction=1.0),
        _terminal(lambda _t, y: y[0] - COLLAPSE_ZETA, direction=-1.0),
        _terminal(lambda _t, y: psi_limit - abs(y[1]), direction=-1.0),
    ]
    solution = solve_ivp(equations, (0.0, STANCE_TIME_CAP), start, method="DOP853", rtol=rtol, atol=atol, events=events)
    nan = (math.nan, math.nan, math.nan)
    if solution.status != 1:
        return (NO_LIFTOFF, *nan)
    first = min(range(3), key=lambda i: solution.t_events[i][0] if solution.t_events[i].size else math.inf)
    if first != 0:
        return ((COLLAPSE, SLIP)[first - 1], *nan)
    _zeta, psi, zeta_dot, psi_dot = solution.y_events[0][0]
    vx = zeta_dot * math.cos(psi) - psi_dot * math.sin(psi)
    vy = zeta_dot * math.sin(psi) + psi_dot * math.cos(psi)
    distance = model.d_hat - math.cos(psi) - next_leg.zeta0 * math.cos(next_leg.psi0)
    if vx <= 0.0 or distance <= 0.0:
        return (NO_FLIGHT, *nan)
    flight_time = distance / vx
    rise = math.sin(psi) + vy * flight_time - 0.5 * flight_time**2 - next_leg.zeta0 * math.sin(next_leg.psi0)
    return OK, -vx, vy - flight_time, rise


def _terminal(function, direction: float):
    function.terminal = True
    function.direction = direction
    return function


def reference_jumps(model: ModelParams, states: np.ndarray, leg: LegControl, next_leg: LegControl, **tolerances):
    """:func:`reference_jump` for each row of ``states``: arrays ``(status, next_states, rises)``."""
    results = [reference_jump(model, state, leg, next_leg, **tolerances) for state in states]
    status = np.array([r[0] for r in results])
    next_states = np.array([r[1:3] for r in results])
    rises = np.array([r[3] for r in results])
    return status, next_states, rises
