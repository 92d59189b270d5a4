"""The deadbeat law: a short horizon on the design model's own map, with a safety guard
(docs/analyses.md, "Controllers").

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
XDOT_STAR, YDOT_STAR, Q_STATE = 14, 15, 16
PARAMETER_COUNT = 17  # then, optionally, the viability guard (sim_core.viability.guard's layout)
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
def horizon_cost(parameters, psi, vx, vy, foot_to_body, next_zeta0, aim_1, aim_2, record):
    """The cost of ``next_zeta0`` from lift-off (``psi`` [rad], velocity ``vx, vy``);
    ``foot_to_body``: how far the two aims lie above this foot. Inf where the model predicts a
    failure within the two jumps."""
    model = design_model(parameters)
    psi0_star, zeta0_star = parameters[PSI0_STAR], parameters[ZETA0_STAR]
    status, xdot, ydot, landed, _ = flight(psi, vx, vy, model.d_hat, psi0_star, next_zeta0)  # landed: above this foot
    if status != OK:
        return math.inf
    # Jump k + 1 (stride.jump, cut at its lift-off for the guard).
    status, psi_1, vx_1, vy_1, _, _ = lift_off(xdot, ydot, psi0_star, next_zeta0, model, record)
    if status != OK:
        return math.inf
    guarded = parameters.size > PARAMETER_COUNT
    if guarded and not lands_in_kernel(parameters, PARAMETER_COUNT, psi_1, vx_1, vy_1, model.d_hat):
        return math.inf
    status, xdot, ydot, touchdown_height, _ = flight(psi_1, vx_1, vy_1, model.d_hat, psi0_star, zeta0_star)
    if status != OK:
        return math.inf
    rise = touchdown_height - zeta0_star * math.sin(psi0_star)
    second = landed - next_zeta0 * math.sin(psi0_star) + rise + zeta0_star * math.sin(psi0_star)
    status, _, _, _, _, _, _ = jump(xdot, ydot, psi0_star, zeta0_star, psi0_star, zeta0_star, model, record)
    if status != OK:  # the gait's controls would not carry on from there
        return math.inf
    miss_1, miss_2 = landed - (aim_1 + foot_to_body), second - (aim_2 + foot_to_body)
    drift = (xdot - parameters[XDOT_STAR]) ** 2 + (ydot - parameters[YDOT_STAR]) ** 2
    return miss_1 * miss_1 + miss_2 * miss_2 + parameters[Q_STATE] * drift


@kernel
def deadbeat_zeta0(parameters, psi0, zeta0, height, xdot, ydot):
    """The next touchdown's zeta0 and whether it was guarded or held at the range's end, from
    touchdown ``k``'s body ``height`` [l0], section state and controls ``(psi0, zeta0)``."""
    record = np.empty((0, STATE_SIZE))
    zeta0_star, low, high = parameters[ZETA0_STAR], parameters[ZETA0_LOW], parameters[ZETA0_HIGH]
    status, psi, vx, vy, _, _ = lift_off(xdot, ydot, psi0, zeta0, design_model(parameters), record)
    if status != OK:  # the stance under way is predicted to fail: nothing later changes that
        return zeta0_star, True
    step = parameters[CLIMB_PER_JUMP]
    error = parameters[TARGET] - height
    aim_1 = min(max(error, -step), step)  # the heights to reach, relative to this one
    aim_2 = min(max(error, -2.0 * step), 2.0 * step)
    foot_to_body = zeta0 * math.sin(psi0)  # this body above this foot, from the controls it touched with
    best, best_cost, at = zeta0_star, math.inf, -1
    spacing = (high - low) / (GRID - 1)
    for i in range(GRID):
        cost = horizon_cost(parameters, psi, vx, vy, foot_to_body, low + i * spacing, aim_1, aim_2, record)
        if cost < best_cost:
            best, best_cost, at = low + i * spacing, cost, i
    if at < 0:  # every candidate is predicted to fail: the gait's own controls
        return zeta0_star, True
    # Golden section on the grid cell either side of the best (the cost is smooth where it is finite).
    a, b = max(best - spacing, low), min(best + spacing, high)
    c, d = b - INVPHI * (b - a), a + INVPHI * (b - a)
    cost_c = horizon_cost(parameters, psi, vx, vy, foot_to_body, c, aim_1, aim_2, record)
    cost_d = horizon_cost(parameters, psi, vx, vy, foot_to_body, d, aim_1, aim_2, record)
    for _ in range(REFINE):
        if cost_c < cost_d:
            b, d, cost_d = d, c, cost_c
            c = b - INVPHI * (b - a)
            cost_c = horizon_cost(parameters, psi, vx, vy, foot_to_body, c, aim_1, aim_2, record)
        else:
            a, c, cost_c = c, d, cost_d
            d = a + INVPHI * (b - a)
            cost_d = horizon_cost(parameters, psi, vx, vy, foot_to_body, d, aim_1, aim_2, record)
    for candidate, cost in ((c, cost_c), (d, cost_d)):
        if cost < best_cost:
            best, best_cost = candidate, cost
    return best, best <= low + 1e-12 or best >= high - 1e-12


def design_deadbeat(
    model, target: float, psi0_deg: float, zeta0_hover: float, *, viability_guard: bool = True, **options
):
    """The law holding ``target`` [l0] about the gait of jumping in place at ``psi0_deg`` with
    ``zeta0_hover``, on ``model`` (its design model), guarded by that model's viability kernel
    unless ``viability_guard`` is False; ``options`` as for :class:`sim_core.control.laws.Deadbeat`."""
    from sim_core.control.laws import Deadbeat
    from sim_core.model.controls import ControlSchedule, LegControl
    from sim_core.model.presets import START_GUESS
    from sim_core.section.gait_search import gait_of
    from sim_core.viability.guard import design_guard

    gait = gait_of(model, ControlSchedule.of(LegControl(math.radians(psi0_deg), zeta0_hover)), guess=START_GUESS)
    state = (float(gait.state[0]), float(gait.state[1]))
    law = Deadbeat(target, psi0_deg, zeta0_hover, state, tuple(model.record()), **options)
    if not viability_guard:
        return law
    return replace(law, guard=design_guard(model, psi0_deg, law.zeta0_range))
