"""A scipy twin of one jump in a world: the world benchmark's baseline and the tests' reference.

Deliberately formulated apart from :mod:`sim_core.world.stride`: the stance in Cartesian
coordinates about the foot (spring and radial damping along the leg, pivot damping across it,
gravity) by scipy's DOP853 with its own event location — the friction cone as the angle of the
leg from the foothold's normal, from ``atan2`` — and the touchdown found by stepping along the
flight and bracketing the first sign change of "foot minus side" with ``brentq``, not by the
kernels' closed-form quadratic.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from sim_core.model.controls import LegControl
from sim_core.model.failures import COLLAPSE, INVALID_STATE, NO_FLIGHT, NO_LIFTOFF, NO_TOUCHDOWN, OK, SLIP
from sim_core.model.integrate import COLLAPSE_ZETA, STANCE_TIME_CAP
from sim_core.model.params import ModelParams
from sim_core.world.geometry import FLIGHT_TIME_CAP
from sim_core.world.world import SIDES, World, inclinations

FLIGHT_STEP = 1e-2  # [sqrt(l0/g)]: the bracketing step along the flight (a crossing shorter than it is missed)


def reference_world_jump(
    model: ModelParams, world: World, touchdown, side: int, leg: LegControl, next_leg: LegControl, *, tol=1e-11
) -> tuple[int, np.ndarray, int]:
    """One jump from ``touchdown`` (the body's ``x, y, xdot, ydot`` in wall coordinates) on
    ``side`` (0 left, 1 right): ``(status, next touchdown, next side)`` (NaNs on failure)."""
    mirror = 1.0 if side == 0 else -1.0
    stance_side, other_side = (world.left, world.right) if side == 0 else (world.right, world.left)
    x, y, xdot, ydot = touchdown
    body = np.array([mirror * x, y])
    velocity = np.array([mirror * xdot, ydot])
    failed = (np.full(4, math.nan), side)
    if velocity[0] >= 0.0:
        return INVALID_STATE, *failed
    foot = body - leg.zeta0 * np.array([math.cos(leg.psi0), math.sin(leg.psi0)])
    beta, mu = _foothold(stance_side, SIDES[side], foot[1], model.mu)
    cone = math.atan(mu)

    def off_normal(r):  # the leg's angle from the foothold's normal
        return math.remainder(math.atan2(r[1], r[0]) - beta, 2 * math.pi)

    if abs(off_normal(body - foot)) >= cone:
        return SLIP, *failed
    alpha, c_zeta, c_psi = model.alpha, model.c_zeta, model.c_psi

    def equations(_t, s):  # plain floats: numpy on two-element vectors would time numpy, not scipy
        x, y, vx, vy = s
        length = math.hypot(x, y)
        ux, uy = x / length, y / length  # along the leg; (-uy, ux) across it
        along = alpha * (1.0 - length) - c_zeta * (vx * ux + vy * uy)
        across = -c_psi * (-vx * uy + vy * ux)
        return [vx, vy, along * ux - across * uy, along * uy + across * ux - 1.0]

    events = [
        _terminal(lambda _t, s: math.hypot(s[0], s[1]) - 1.0, 1.0),
        _terminal(lambda _t, s: math.hypot(s[0], s[1]) - COLLAPSE_ZETA, -1.0),
        _terminal(lambda _t, s: cone - abs(off_normal(s[:2])), -1.0),
    ]
    start = [*(body - foot), *velocity]
    solution = solve_ivp(equations, (0.0, STANCE_TIME_CAP), start, method="DOP853", rtol=tol, atol=tol, events=events)
    if solution.status != 1:
        return NO_LIFTOFF, *failed
    first = min(range(3), key=lambda i: solution.t_events[i][0] if solution.t_events[i].size else math.inf)
    if first != 0:
        return (COLLAPSE, SLIP)[first - 1], *failed
    lift = solution.y_events[0][0]
    reach = next_leg.zeta0 * np.array([math.cos(next_leg.psi0), -math.sin(next_leg.psi0)])
    next_foot = foot + lift[:2] + reach
    vx, vy = lift[2:]

    def gap(t):  # the coming foot's x minus the other side's, at the foot's height
        height = next_foot[1] + vy * t - 0.5 * t * t
        return next_foot[0] + vx * t - mirror * other_side.x_at(height)

    if vx <= 0.0 or gap(0.0) >= 0.0:
        return NO_FLIGHT, *failed
    times = np.arange(FLIGHT_STEP, FLIGHT_TIME_CAP + FLIGHT_STEP, FLIGHT_STEP)
    heights = next_foot[1] + vy * times - 0.5 * times**2
    gaps = next_foot[0] + vx * times - mirror * np.interp(heights, other_side.points[:, 1], other_side.points[:, 0])
    crossed = np.flatnonzero(gaps >= 0.0)
    if crossed.size == 0:
        return NO_TOUCHDOWN, *failed
    after = times[crossed[0]]
    t = brentq(gap, after - FLIGHT_STEP, after, xtol=1e-14, rtol=4 * np.finfo(float).eps)
    landed = next_foot + np.array([vx * t, vy * t - 0.5 * t * t]) - reach
    return OK, np.array([mirror * landed[0], landed[1], mirror * vx, vy - t]), 1 - side


def _foothold(side, name: str, foot_y: float, model_mu: float) -> tuple[float, float]:
    """``(beta, mu)`` of the segment under a foot at ``foot_y`` (a vertex belongs to the one above)."""
    heights = side.points[:, 1]
    segment = int(np.searchsorted(heights, foot_y, side="right")) - 1
    if segment < 0 or segment >= len(heights) - 1:
        return 0.0, model_mu
    return float(inclinations(side.points, name)[segment]), float(side.friction(model_mu)[segment])


def _terminal(function, direction: float):
    function.terminal = True
    function.direction = direction
    return function
