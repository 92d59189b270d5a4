"""A world's jump from the chute's centre line to the centre line, compiled: the step map of
viability in a world (:mod:`sim_core.viability.world_step_map`, docs/model.md §8).

On parallel walls the mid-chute section needs only the velocity (:mod:`sim_core.model.noisy_map`);
in a world the height matters too, and the side the body flies toward: the state is the body
crossing ``x = 0`` at height ``y`` [l0] with velocity ``(xdot, ydot)`` in wall coordinates, the
sign of ``xdot`` saying which side comes next (``< 0``: the left one). Nothing of the coming jump
is chosen yet, so the action is the coming leg's ``(psi0, zeta0)``, held in flight: the foot
meets the coming side in closed form (:func:`sim_core.world.geometry.first_crossing`), the stance
runs in its foothold's cone, and the body flies back to ``x = 0``. It fails as a world's jump
fails, and at the floor (docs/model.md §7.2): a touchdown or a crossing with the body below it.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.model.failures import FLOOR, FLOOR_HEIGHT, INVALID_STATE, NO_FLIGHT, NO_TOUCHDOWN, OK
from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, ZETA_DOT
from sim_core.model.stride import liftoff_velocity
from sim_core.world.geometry import FLIGHT_TIME_CAP, first_crossing
from sim_core.world.stride import foothold_stance


@kernel
def centre_step(y, xdot, ydot, psi0, zeta0, model, sides, no_record):
    """One jump from the centre line to the centre line: ``(status, y, xdot, ydot)`` of the next
    crossing (wall coordinates; NaNs after a failure)."""
    nan = math.nan
    if not (math.isfinite(y + xdot + ydot + psi0 + zeta0) and xdot != 0.0 and 0.0 < zeta0 < 1.0):
        return INVALID_STATE, nan, nan, nan
    side = 0 if xdot < 0.0 else 1
    mirror = 1.0 if side == 0 else -1.0  # the coming side's stance frame: x -> mirror * x
    # The coming foot, held at (psi0, zeta0), meets its side: in the frame that puts that side on
    # the right (x -> -mirror * x), as first_crossing reads a side
    foot_x, foot_y = zeta0 * math.cos(psi0), y - zeta0 * math.sin(psi0)  # its x, mirrored
    flight, segment = first_crossing(sides, side, -mirror, foot_x, foot_y, -mirror * xdot, ydot)
    if not flight <= FLIGHT_TIME_CAP:
        return NO_TOUCHDOWN, nan, nan, nan
    vx, vy = mirror * xdot, ydot - flight  # at touchdown, in the stance frame
    touchdown_y = y + (ydot - 0.5 * flight) * flight
    if touchdown_y < FLOOR_HEIGHT:
        return FLOOR, nan, nan, nan
    foot_x_stance = -(foot_x + -mirror * xdot * flight)  # the stance frame's x of the foot
    foot_y_stance = touchdown_y - zeta0 * math.sin(psi0)
    final = np.empty(STATE_SIZE)
    status, _ = foothold_stance(vx, vy, psi0, zeta0, model, sides, side, segment, final, no_record)
    if status != OK:
        return status, nan, nan, nan
    psi = final[PSI]
    lift_x, lift_y = foot_x_stance + math.cos(psi), foot_y_stance + math.sin(psi)
    out_x, out_y = liftoff_velocity(psi, final[ZETA_DOT], final[PSI_DOT])
    if out_x <= 0.0 or lift_x >= 0.0:  # heading back, and still short of the centre line
        return NO_FLIGHT, nan, nan, nan
    back = -lift_x / out_x
    next_y = lift_y + (out_y - 0.5 * back) * back
    if next_y < FLOOR_HEIGHT:
        return FLOOR, nan, nan, nan
    return OK, next_y, mirror * out_x, out_y - back
