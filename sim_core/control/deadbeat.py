"""The deadbeat law and the placement law between walls: a short horizon on the design model's own
map, with a safety guard (docs/analyses.md, "Controllers").

At touchdown ``k`` the robot knows the section state ``(xdot, ydot)``, its body height and the
controls it touched down with, so the model fixes the stance under way and its lift-off
(:func:`sim_core.model.stride.lift_off`); the flight after it is closed form. Landing the next body
height on the target in one jump (deadbeat on the height alone) is easy and fails: the leg
length that lands the body also sets the energy of the next stance, and chasing the height
pumps energy until the robot flies off (the issue's prototype: 30/30 failed, ``no_flight``).
So the law looks two jumps ahead: for each candidate zeta0 of touchdown ``k + 1`` (the leg
angle nominal) it predicts touchdowns ``k + 1`` and ``k + 2`` (the one after held at the gait's
controls) and takes the candidate of least

    (h_{k+1} - a_1)² + (h_{k+2} - a_2)² + q_state |s_{k+2} - s*|²,

where ``a_j`` is the height ``j`` climbs of at most ``climb_per_jump`` [l0] toward the target
and ``s*`` the gait's section state: the height reached soon, with the state kept near the gait
so that what follows is the gait again. Candidates are a grid over the leg's range, the best
refined by golden section.

The guard: a candidate for which the model predicts jump ``k + 1`` or ``k + 2`` fails is never
sent, nor (with the viability guard, :mod:`sim_core.viability.guard`, on by default) one whose
jump ``k + 1`` leaves the model's viability kernel for this leg angle and zeta0 range: every
command is a viable state-action pair, one from which some command sequence goes on forever,
not merely two jumps. If every candidate is refused (or the stance under way is predicted to
fail), the gait's own controls go out. A command at the range's end, or sent because nothing else was safe, counts
as saturated.

The placement law (``placement``) is the same horizon over both legs: the best zeta0 at the gait's
angle, then golden section about it at the angle ``ANGLE_STEP`` below and above (within the
servos' range), the least cost of the three, with a lighter ``q_state`` so that the feet's
heights lead. Between parallel walls every foothold is the other wall, so placing the next foot
is placing it at a height; on footholds :mod:`sim_core.control.placement` follows a plan.

Everything runs on the *design* model (a calibrated preset's, or the paper's), which the law
carries: on the robot it predicts with what it was designed on, not with the hidden truth.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from sim_core._jit import kernel
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelRecord
from sim_core.model.stride import flight, jump, lift_off
from sim_core.viability.guard import lands_in_kernel

# Parameter layout of the compiled law (sim_core.control.laws.Deadbeat.kernel_args).
TARGET, PSI0_STAR, ZETA0_STAR, ZETA0_LOW, ZETA0_HIGH, PSI0_LOW, PSI0_HIGH, CLIMB_PER_JUMP, PITCH_GAIN = range(9)
MODEL = 9  # the design model's ModelRecord fields, in their order (alpha, d_hat, c_zeta, c_psi, mu)
XDOT_STAR, YDOT_STAR, Q_STATE, ANGLE_STEP = 14, 15, 16, 17  # ANGLE_STEP [rad]: 0 holds the angle (deadbeat)
PARAMETER_COUNT = 18  # then, optionally, the viability guard (sim_core.viability.guard's layout)
GRID = 13  # candidates over the leg's range
REFINE = 8  # golden-section steps about the best
INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


@kernel
def design_model(parameters):
    """The design model's record (:class:`sim_core.model.params.ModelRecord`) from the law's
    parameters, where :meth:`sim_core.control.laws.Deadbeat.kernel_args` lays it out."""
    return ModelRecord(
        parameters[MODEL], parameters[MODEL + 1], parameters[MODEL + 2], parameters[MODEL + 3], parameters[MODEL + 4]
    )


@kernel
def horizon_cost(parameters, psi, vx, vy, foot_to_body, next_psi0, next_zeta0, aim_1, aim_2, record):
    """The cost of the next leg ``(next_psi0, next_zeta0)`` from lift-off (``psi`` [rad], velocity ``vx, vy``);
    ``foot_to_body``: how far the two aims lie above this foot. Inf where the model predicts a
    failure within the two jumps."""
    model = design_model(parameters)
    psi0_star, zeta0_star = parameters[PSI0_STAR], parameters[ZETA0_STAR]
    status, xdot, ydot, landed, _ = flight(psi, vx, vy, model.d_hat, next_psi0, next_zeta0)  # landed: above this foot
    if status != OK:
        return math.inf
    # Jump k + 1 (stride.jump, cut at its lift-off for the guard).
    status, psi_1, vx_1, vy_1, _, _ = lift_off(xdot, ydot, next_psi0, next_zeta0, model, record)
    if status != OK:
        return math.inf
    guarded = parameters.size > PARAMETER_COUNT
    if guarded and not lands_in_kernel(parameters, PARAMETER_COUNT, psi_1, vx_1, vy_1, model.d_hat):
        return math.inf
    status, xdot, ydot, touchdown_height, _ = flight(psi_1, vx_1, vy_1, model.d_hat, psi0_star, zeta0_star)
    if status != OK:
        return math.inf
    rise = touchdown_height - zeta0_star * math.sin(psi0_star)
    second = landed - next_zeta0 * math.sin(next_psi0) + rise + zeta0_star * math.sin(psi0_star)
    status, _, _, _, _, _, _ = jump(xdot, ydot, psi0_star, zeta0_star, psi0_star, zeta0_star, model, record)
    if status != OK:  # the gait's controls would not carry on from there
        return math.inf
    miss_1, miss_2 = landed - (aim_1 + foot_to_body), second - (aim_2 + foot_to_body)
    drift = (xdot - parameters[XDOT_STAR]) ** 2 + (ydot - parameters[YDOT_STAR]) ** 2
    return miss_1 * miss_1 + miss_2 * miss_2 + parameters[Q_STATE] * drift


@kernel
def deadbeat_leg(parameters, psi0, zeta0, height, xdot, ydot):
    """The next touchdown's ``(psi0 [rad], zeta0)`` and whether it was guarded or held at the range's
    end, from touchdown ``k``'s body ``height`` [l0], section state and controls ``(psi0, zeta0)``:
    zeta0 over its range at the gait's angle and, where the law's ``ANGLE_STEP`` is not 0 (the
    placement law), at that angle either side of it too; the best of each refined."""
    record = np.empty((0, STATE_SIZE))
    psi0_star, zeta0_star = parameters[PSI0_STAR], parameters[ZETA0_STAR]
    status, psi, vx, vy, _, _ = lift_off(xdot, ydot, psi0, zeta0, design_model(parameters), record)
    if status != OK:  # the stance under way is predicted to fail: nothing later changes that
        return psi0_star, zeta0_star, True
    step = parameters[CLIMB_PER_JUMP]
    error = parameters[TARGET] - height
    aim_1 = min(max(error, -step), step)  # the heights to reach, relative to this one
    aim_2 = min(max(error, -2.0 * step), 2.0 * step)
    foot_to_body = zeta0 * math.sin(psi0)  # this body above this foot, from the controls it touched with
    angles = 1 if parameters[ANGLE_STEP] == 0.0 else 3
    best_psi0 = psi0_star
    best, best_cost = _best_length(parameters, psi, vx, vy, foot_to_body, psi0_star, math.nan, aim_1, aim_2, record)
    if best_cost == math.inf:  # every candidate is predicted to fail: the gait's own controls
        return psi0_star, zeta0_star, True
    at_gait = best
    for a in range(1, angles):  # a step below and above the gait's angle, about the length found there
        angle = psi0_star + (-1.0, 1.0)[a - 1] * parameters[ANGLE_STEP]
        if not parameters[PSI0_LOW] <= angle <= parameters[PSI0_HIGH]:
            continue  # past the servos' range
        zeta0_next, cost = _best_length(parameters, psi, vx, vy, foot_to_body, angle, at_gait, aim_1, aim_2, record)
        if cost < best_cost:
            best_psi0, best, best_cost = angle, zeta0_next, cost
    low, high = parameters[ZETA0_LOW], parameters[ZETA0_HIGH]
    return best_psi0, best, best <= low + 1e-12 or best >= high - 1e-12


@kernel
def _best_length(parameters, psi, vx, vy, foot_to_body, angle, about, aim_1, aim_2, record):
    """The least-cost zeta0 at leg angle ``angle`` and its cost (inf: every one predicted to fail):
    the range's grid, then golden section about the best; where ``about`` is a length (not NaN),
    golden section about it alone."""
    low, high = parameters[ZETA0_LOW], parameters[ZETA0_HIGH]
    best, best_cost = parameters[ZETA0_STAR], math.inf
    spacing = (high - low) / (GRID - 1)
    if math.isnan(about):
        for i in range(GRID):
            cost = horizon_cost(parameters, psi, vx, vy, foot_to_body, angle, low + i * spacing, aim_1, aim_2, record)
            if cost < best_cost:
                best, best_cost = low + i * spacing, cost
        if best_cost == math.inf:
            return best, best_cost
    else:
        best = about
    # Golden section on the grid cell either side of the best (the cost is smooth where it is finite).
    a, b = max(best - spacing, low), min(best + spacing, high)
    c, d = b - INVPHI * (b - a), a + INVPHI * (b - a)
    cost_c = horizon_cost(parameters, psi, vx, vy, foot_to_body, angle, c, aim_1, aim_2, record)
    cost_d = horizon_cost(parameters, psi, vx, vy, foot_to_body, angle, d, aim_1, aim_2, record)
    for _ in range(REFINE):
        if cost_c < cost_d:
            b, d, cost_d = d, c, cost_c
            c = b - INVPHI * (b - a)
            cost_c = horizon_cost(parameters, psi, vx, vy, foot_to_body, angle, c, aim_1, aim_2, record)
        else:
            a, c, cost_c = c, d, cost_d
            d = a + INVPHI * (b - a)
            cost_d = horizon_cost(parameters, psi, vx, vy, foot_to_body, angle, d, aim_1, aim_2, record)
    for candidate, cost in ((c, cost_c), (d, cost_d)):
        if cost < best_cost:
            best, best_cost = candidate, cost
    return best, best_cost


def design_deadbeat(
    model, target: float, psi0_deg: float, zeta0_hover: float, *, viability_guard: bool = True, law=None, **options
):
    """The law holding ``target`` [l0] about the gait of jumping in place at ``psi0_deg`` with
    ``zeta0_hover``, on ``model`` (its design model), guarded by that model's viability kernel
    unless ``viability_guard`` is False; ``law``: :class:`sim_core.control.laws.Deadbeat` (the
    default) or :class:`~sim_core.control.laws.Placement`; ``options`` as for it."""
    from sim_core.control.laws import Deadbeat
    from sim_core.model.controls import ControlSchedule, LegControl
    from sim_core.model.presets import START_GUESS
    from sim_core.section.gait_search import gait_of
    from sim_core.viability.guard import design_guard

    gait = gait_of(model, ControlSchedule.of(LegControl(math.radians(psi0_deg), zeta0_hover)), guess=START_GUESS)
    state = (float(gait.state[0]), float(gait.state[1]))
    designed = (law or Deadbeat)(target, psi0_deg, zeta0_hover, state, tuple(model.record()), **options)
    if not viability_guard:
        return designed
    return replace(designed, guard=design_guard(model, psi0_deg, designed.zeta0_range))
