"""The foot-placement law: the next leg's ``psi0`` and ``zeta0`` chosen so that its foot lands on
the foothold a plan names, with a margin from the foothold's ends and inside its friction cone
(docs/model.md §8; docs/worlds.md, "Following a plan").

The legs may be chosen up to lift-off (docs/model.md §2.1), and the law decides there
(:func:`place_from_liftoff`): the tracker sees the body leave the wall, so what the stance made of
the leg's noise is known, and the flight after it is a parabola — where the coming foot first
meets the other side is a quadratic per segment (:func:`sim_core.world.stride.world_flight`).
(:func:`place_leg` decides at touchdown instead: it reads the leg's angle off the tracked body —
the foot is on the wall, :func:`leg_on_wall` — and predicts the stance on the model; the length's
noise stays unseen there, and measured, that alone halves how often a plan is followed to its
goal.) The law tries a grid of next legs — the angles inside the target foothold's cone, the
lengths over the leg's range — and the plan's own leg. A candidate is *good* if its foot lands on
the target segment at least ``end_margin`` [l0] along it from either end (a quarter of a short
foothold at most), its angle at least ``cone_margin`` [rad] inside the cone (half the cone at
most) and the body above the floor. Good candidates are costed by

    ((y_foot - y_aim) / position_scale)² + |v - v_aim|² / velocity_scale²
        + ((psi0 - psi0_aim) / psi0_scale)² + ((zeta0 - zeta0_aim) / zeta0_scale)²

against the plan's touchdown ``k + 1`` (its foot, the body's velocity there, its leg); the
:data:`AHEAD` cheapest are looked at one jump further — the jump each sets off with the plan's
following leg must land on the plan's next foothold with the same margins, above the floor (the
guard), and its touchdown is costed the same way against the plan's ``k + 2`` — and the least
total wins (``found`` :data:`PLACED`). With no good candidate the guard passes, the plan's own
leg if it lands on the target and goes on, else the widest margin that lands there
(:data:`TIGHT`); with none that lands there, the plan's leg (:data:`OFF_PLAN`). A caller replans
on anything but PLACED (:mod:`sim_core.planning.follow`).

The time is bounded: ``PSI0_GRID x ZETA0_GRID + 1`` flights and at most :data:`AHEAD` jumps (one
stance more from a touchdown); about 50-60 µs a jump on one core (docs/worlds.md).
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.model.failures import FLOOR_HEIGHT, OK
from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, ZETA_DOT
from sim_core.model.stride import liftoff_velocity
from sim_core.world.geometry import side_x
from sim_core.world.stride import foothold_stance, world_flight, world_jump

# The aim (what the plan says of touchdown k + 1): its segment on the other side, its foot [l0],
# the body's velocity there [sqrt(g l0)] and its leg; then of touchdown k + 2: the leg that sets it
# down, its foot's height and the body's velocity (NaN: the plan ends at k + 1)
AIM_SEGMENT, AIM_X, AIM_Y, AIM_XDOT, AIM_YDOT, AIM_PSI0, AIM_ZETA0 = range(7)
THEN_PSI0, THEN_ZETA0, THEN_Y, THEN_XDOT, THEN_YDOT, THEN_SEGMENT = range(7, 13)
AIM_SIZE = 13
# The settings: the leg's range [rad, l0], the margins [l0, rad] and the cost's scales
PSI0_LOW, PSI0_HIGH, ZETA0_LOW, ZETA0_HIGH, END_MARGIN, CONE_MARGIN = range(6)
POSITION_SCALE, VELOCITY_SCALE, PSI0_SCALE, ZETA0_SCALE = range(6, 10)
SETTINGS_SIZE = 10
PSI0_GRID, ZETA0_GRID = 13, 9
AHEAD = 12  # the best landings looked at one jump further
NEWTON_STEPS, MAX_TURN = 6, 0.2  # the leg angle found from the tracked body: its steps, and how far [rad] it may be
OFF_PLAN, TIGHT, PLACED = 0, 1, 2  # what `found` says


@kernel
def place_leg(model, sides, x, y, xdot, ydot, side, segment, psi0, zeta0, aim, settings):
    """The next leg for the foothold ``aim`` names, decided at touchdown ``k``: the body ``x, y,
    xdot, ydot`` (wall coordinates) on ``side``'s ``segment``, touched down with ``(psi0, zeta0)``
    as sent (the angle turned by the pitch it knew); the lift-off predicted on the model
    (:func:`place_from_liftoff` takes it as tracked). Returns ``(found, psi0, zeta0)`` as there."""
    record = np.empty((0, STATE_SIZE))
    mirror = 1.0 if side == 0 else -1.0
    psi0 = leg_on_wall(sides, side, x, y, psi0, zeta0)
    final = np.empty(STATE_SIZE)
    status, _ = foothold_stance(mirror * xdot, ydot, psi0, zeta0, model, sides, side, segment, final, record)
    if status != OK:  # the stance under way fails: nothing chosen now changes that
        return OFF_PLAN, aim[AIM_PSI0], aim[AIM_ZETA0]
    vx, vy = liftoff_velocity(final[PSI], final[ZETA_DOT], final[PSI_DOT])
    hip_x = x - mirror * zeta0 * math.cos(psi0) + mirror * math.cos(final[PSI])
    hip_y = y - zeta0 * math.sin(psi0) + math.sin(final[PSI])
    return place_from_liftoff(model, sides, side, hip_x, hip_y, mirror * vx, vy, aim, settings)


@kernel
def place_from_liftoff(model, sides, side, x, y, xdot, ydot, aim, settings):
    """The next leg for the foothold ``aim`` names, decided at lift-off off ``side``: the body at
    ``x, y`` with velocity ``xdot, ydot`` (wall coordinates, tracked). Returns ``(found, psi0,
    zeta0)``: ``found`` as :data:`PLACED`, :data:`TIGHT` or :data:`OFF_PLAN` (the module); the
    angle in the landing side's stance frame, before any pitch correction."""
    record = np.empty((0, STATE_SIZE))
    other, target = 1 - side, int(aim[AIM_SEGMENT])
    beta = sides.beta[other, target + 1]
    half = math.atan(sides.friction[other, target + 1])
    cone_margin = min(settings[CONE_MARGIN], 0.5 * half)
    psi0_low = max(settings[PSI0_LOW], beta - half + cone_margin)
    psi0_high = min(settings[PSI0_HIGH], beta + half - cone_margin)
    if psi0_low > psi0_high:  # the leg's range misses the cone's core: try the whole cone in range
        psi0_low, psi0_high = max(settings[PSI0_LOW], beta - half), min(settings[PSI0_HIGH], beta + half)
        if psi0_low > psi0_high:
            return OFF_PLAN, aim[AIM_PSI0], aim[AIM_ZETA0]
    zeta0_low, zeta0_high = settings[ZETA0_LOW], settings[ZETA0_HIGH]
    psi0_step = (psi0_high - psi0_low) / (PSI0_GRID - 1)
    zeta0_step = (zeta0_high - zeta0_low) / (ZETA0_GRID - 1)
    grid = PSI0_GRID * ZETA0_GRID + 1
    legs = np.empty((grid, 2))
    costs = np.full(grid, math.inf)
    for i in range(grid - 1):
        legs[i, 0] = psi0_low + (i // ZETA0_GRID) * psi0_step
        legs[i, 1] = zeta0_low + (i % ZETA0_GRID) * zeta0_step
    legs[grid - 1, 0], legs[grid - 1, 1] = aim[AIM_PSI0], aim[AIM_ZETA0]  # the plan's own leg, where it lands
    liftoff = (x, y, xdot, ydot)
    for i in range(grid):
        if _margin(sides, side, liftoff, target, legs[i, 0], legs[i, 1], settings) >= 1.0:
            costs[i] = _landing_cost(sides, side, liftoff, legs[i, 0], legs[i, 1], aim, settings)
    # The best by the landing alone, looked at one jump further: the jump each sets off, with the
    # plan's following leg, must reach the plan's next foothold with the margins (the guard), and
    # where it lands is costed too
    best, best_cost = -1, math.inf
    for _ in range(AHEAD):
        candidate = int(np.argmin(costs))
        if not math.isfinite(costs[candidate]):
            break
        ahead = _ahead_cost(model, sides, side, liftoff, legs[candidate, 0], legs[candidate, 1], aim, settings,
                            record)  # fmt: skip
        if costs[candidate] + ahead < best_cost:
            best, best_cost = candidate, costs[candidate] + ahead
        costs[candidate] = math.inf
    if best >= 0:
        return PLACED, legs[best, 0], legs[best, 1]
    # No good leg the guard passes: the plan's own if it lands on the target and goes on, else the
    # widest margin that lands there
    plan_psi0, plan_zeta0 = aim[AIM_PSI0], aim[AIM_ZETA0]
    on_target = _margin(sides, side, liftoff, target, plan_psi0, plan_zeta0, settings) > 0.0
    if on_target and math.isfinite(
        _ahead_cost(model, sides, side, liftoff, plan_psi0, plan_zeta0, aim, settings, record)
    ):
        return TIGHT, plan_psi0, plan_zeta0
    best_margin, widest = -math.inf, -1
    for i in range(grid):
        margin = _margin(sides, side, liftoff, target, legs[i, 0], legs[i, 1], settings)
        if margin > best_margin:
            best_margin, widest = margin, i
    if widest < 0 or best_margin == -math.inf:
        return OFF_PLAN, plan_psi0, plan_zeta0
    return TIGHT, legs[widest, 0], legs[widest, 1]


@kernel
def leg_on_wall(sides, side, x, y, psi0, zeta0):
    """The leg angle [rad] that puts the foot of a body at ``(x, y)`` (tracked) on ``side``'s
    polyline with the leg at ``zeta0``, found from ``psi0`` (the angle as sent, turned by the pitch)
    by Newton's steps — the root nearest it, where a kinked side has two; ``psi0`` itself where
    they do not settle within ``MAX_TURN``. The foot is on the wall, so the body's place tells the
    angle the noise gave the leg (for the length sent: its own noise stays unseen)."""
    mirror = 1.0 if side == 0 else -1.0
    step, angle = 1e-7, psi0
    for _ in range(NEWTON_STEPS):
        gap = _off_wall(sides, side, mirror, x, y, angle, zeta0)
        if abs(gap) < 1e-12:
            return angle
        slope = (_off_wall(sides, side, mirror, x, y, angle + step, zeta0) - gap) / step
        if slope == 0.0 or not math.isfinite(slope):
            return psi0
        angle -= gap / slope
    if abs(_off_wall(sides, side, mirror, x, y, angle, zeta0)) < 1e-9 and abs(angle - psi0) < MAX_TURN:
        return angle
    return psi0


@kernel
def _off_wall(sides, side, mirror, x, y, psi0, zeta0):
    """How far [l0] the foot of a body at ``(x, y)`` with the leg ``(psi0, zeta0)`` lies off the wall,
    along x in the side's stance frame."""
    return mirror * x - zeta0 * math.cos(psi0) - mirror * side_x(sides, side, y - zeta0 * math.sin(psi0))


@kernel
def _end_margin(sides, other, segment, foot_y):
    """How far along ``segment`` [l0] ``foot_y`` lies from its nearer end, and the most that can
    be asked on it (a quarter of its length); the continuations are open on their far side."""
    points, last = sides.points[other], sides.counts[other] - 1
    if segment < 0:
        return points[0, 1] - foot_y, math.inf
    if segment >= last:
        return foot_y - points[last, 1], math.inf
    xa, ya, xb, yb = points[segment, 0], points[segment, 1], points[segment + 1, 0], points[segment + 1, 1]
    length = math.hypot(xb - xa, yb - ya)
    share = (foot_y - ya) / (yb - ya)
    return min(share, 1.0 - share) * length, 0.25 * length


@kernel
def _margin(sides, side, liftoff, target, psi0, zeta0, settings):
    """A landing's margin on the target in units of what is asked (>= 1: good); -inf off it or
    below the floor."""
    status, _, body_y, _, _, segment, _ = world_flight(*liftoff, side, psi0, zeta0, sides)
    if status != OK or segment != target or body_y < FLOOR_HEIGHT:
        return -math.inf
    return landing_margin(sides, 1 - side, segment, body_y - zeta0 * math.sin(psi0), psi0, settings)


@kernel
def landing_margin(sides, side, segment, foot_y, psi0, settings):
    """A foot's margin on ``side``'s ``segment`` at height ``foot_y`` [l0] with the leg at ``psi0``
    [rad], in units of what the law asks (>= 1: good): the smaller of its distance from the nearer
    end over ``END_MARGIN`` (a quarter of a shorter foothold) and its angle inside the friction cone
    over ``CONE_MARGIN`` (half the cone at most)."""
    along, most = _end_margin(sides, side, segment, foot_y)
    half = math.atan(sides.friction[side, segment + 1])
    cone = half - abs(psi0 - sides.beta[side, segment + 1])
    return min(along / min(settings[END_MARGIN], most), cone / min(settings[CONE_MARGIN], 0.5 * half))


@kernel
def _landing_cost(sides, side, liftoff, psi0, zeta0, aim, settings):
    """A landing's cost against the plan's touchdown ``k + 1`` (its foot, velocity and leg)."""
    _, _, body_y, xdot, ydot, _, _ = world_flight(*liftoff, side, psi0, zeta0, sides)
    return (
        miss_cost(settings, body_y - zeta0 * math.sin(psi0), xdot, ydot, aim[AIM_Y], aim[AIM_XDOT], aim[AIM_YDOT])
        + ((psi0 - aim[AIM_PSI0]) / settings[PSI0_SCALE]) ** 2
        + ((zeta0 - aim[AIM_ZETA0]) / settings[ZETA0_SCALE]) ** 2
    )


@kernel
def miss_cost(settings, foot_y, xdot, ydot, aim_y, aim_xdot, aim_ydot):
    """How far a touchdown (its foot's height [l0], the body's velocity) is from its aim, in the
    cost's scales; an aim of NaN height costs nothing."""
    if math.isnan(aim_y):
        return 0.0
    velocity = ((xdot - aim_xdot) ** 2 + (ydot - aim_ydot) ** 2) / settings[VELOCITY_SCALE] ** 2
    return ((foot_y - aim_y) / settings[POSITION_SCALE]) ** 2 + velocity


@kernel
def _ahead_cost(model, sides, side, liftoff, psi0, zeta0, aim, settings, record):
    """The jump after a landing with ``(psi0, zeta0)``, with the plan's following leg, on the
    model: how far its touchdown is from the plan's (:func:`miss_cost`); inf if it fails, misses the
    plan's next foothold or lands there without the margins (the guard); 0 where the plan ends at
    the landing (a NaN following leg)."""
    then_psi0, then_zeta0 = aim[THEN_PSI0], aim[THEN_ZETA0]
    if math.isnan(then_psi0):  # the plan ends at this touchdown: nothing after it to guard
        return 0.0
    _, x, y, xdot, ydot, segment, _ = world_flight(*liftoff, side, psi0, zeta0, sides)
    status, _, y, xdot, ydot, _, landing, _, _, _ = world_jump(
        x, y, xdot, ydot, 1 - side, segment, psi0, zeta0, then_psi0, then_zeta0, model, sides, record
    )
    if status != OK or y < FLOOR_HEIGHT or landing != aim[THEN_SEGMENT]:
        return math.inf
    foot_y = y - then_zeta0 * math.sin(then_psi0)
    along, most = _end_margin(sides, side, landing, foot_y)
    half = math.atan(sides.friction[side, landing + 1])
    cone = half - abs(then_psi0 - sides.beta[side, landing + 1])
    if along < min(settings[END_MARGIN], most) or cone < min(settings[CONE_MARGIN], 0.5 * half):
        return math.inf  # the plan's next foothold reached, but without the margins the law keeps
    return miss_cost(settings, foot_y, xdot, ydot, aim[THEN_Y], aim[THEN_XDOT], aim[THEN_YDOT])
