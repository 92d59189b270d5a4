"""An independent reference for the ParkourBot map: Cartesian coordinates, real wall frame.

Deliberately shares nothing with sim_core's kernels but the failure codes and thresholds:
the stance is integrated in Cartesian coordinates about the foot (spring force along the
leg, radial and tangential viscous damping — the forces behind paper eq. 3) with scipy's
DOP853 at tight tolerance, and the body really alternates between the left and the right
wall: no coordinate flip. Agreement therefore checks the polar equations, the event
handling, the flight and the flip together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from sim_core.model.failures import COLLAPSE, NO_FLIGHT, NO_LIFTOFF, OK, SLIP
from sim_core.model.integrate import COLLAPSE_ZETA, STANCE_TIME_CAP

TOLERANCE = 1e-13  # tighter than the kernel (1e-12) so differences measure the kernel


@dataclass
class ReferenceRun:
    section_states: list  # flipped-frame (xdot, ydot) at each touchdown
    rises: list
    status: int  # OK or the failure of the jump after the last completed one


def run(params, schedule_deg, section_state, jumps, tolerance=TOLERANCE) -> ReferenceRun:
    """``params``: dict alpha, d_hat, c_zeta, c_psi, mu; ``schedule_deg``: [(psi0 deg, zeta0)]."""
    alpha, d_hat = params["alpha"], params["d_hat"]
    c_zeta, c_psi, mu = params["c_zeta"], params["c_psi"], params["mu"]
    legs = [(math.radians(psi), zeta) for psi, zeta in schedule_deg]
    side = 1.0  # +1: stance on the left wall (x = -d/2); -1: on the right wall
    psi0, zeta0 = legs[0]
    foot = np.array([-side * d_hat / 2, 0.0])
    position = foot + zeta0 * np.array([side * math.cos(psi0), math.sin(psi0)])
    velocity = np.array([section_state[0], section_state[1]])  # left wall: no flip
    sections = [velocity.copy()]
    rises = []
    for k in range(jumps):
        next_psi0, next_zeta0 = legs[(k + 1) % len(legs)]

        def forces(_t, y, foot=foot):
            r = y[:2] - foot
            v = y[2:]
            length = math.hypot(r[0], r[1])
            radial = r / length
            tangential = np.array([-radial[1], radial[0]])
            accel = (
                alpha * (1.0 - length) * radial
                - np.array([0.0, 1.0])
                - c_zeta * (v @ radial) * radial
                - c_psi * (v @ tangential) * tangential
            )
            return [v[0], v[1], accel[0], accel[1]]

        def liftoff(_t, y, foot=foot):
            return math.hypot(*(y[:2] - foot)) - 1.0

        def collapse(_t, y, foot=foot):
            return math.hypot(*(y[:2] - foot)) - COLLAPSE_ZETA

        def slip(_t, y, foot=foot, side=side):
            # Outside the cone |r_y| > mu |r_x|; with mu = inf, once the body passes over the foot.
            r = y[:2] - foot
            return mu * side * r[0] - abs(r[1]) if math.isfinite(mu) else side * r[0]

        events = [liftoff, collapse, slip]
        liftoff.direction, collapse.direction, slip.direction = 1.0, -1.0, -1.0
        for event in events:
            event.terminal = True
        solution = solve_ivp(
            forces,
            (0.0, STANCE_TIME_CAP),
            np.concatenate([position, velocity]),
            method="DOP853",
            rtol=tolerance,
            atol=tolerance,
            events=events,
        )
        if solution.status != 1:
            return ReferenceRun(sections, rises, NO_LIFTOFF)
        times = [t[0] if t.size else math.inf for t in solution.t_events]
        first = int(np.argmin(times))
        if first == 1:
            return ReferenceRun(sections, rises, COLLAPSE)
        if first == 2:
            return ReferenceRun(sections, rises, SLIP)
        end = solution.y_events[0][0]
        position, velocity = end[:2], end[2:]
        # Flight toward the other wall, to where the next leg's foot touches it.
        touchdown_x = side * (d_hat / 2 - next_zeta0 * math.cos(next_psi0))
        flight_time = (touchdown_x - position[0]) / velocity[0] if velocity[0] != 0 else -1.0
        if side * velocity[0] <= 0 or flight_time <= 0:
            return ReferenceRun(sections, rises, NO_FLIGHT)
        position = np.array([touchdown_x, position[1] + velocity[1] * flight_time - flight_time**2 / 2])
        velocity = np.array([velocity[0], velocity[1] - flight_time])
        side = -side
        next_foot = np.array([-side * d_hat / 2, position[1] - next_zeta0 * math.sin(next_psi0)])
        rises.append(next_foot[1] - foot[1])
        foot = next_foot
        sections.append(np.array([side * velocity[0], velocity[1]]))
    return ReferenceRun(sections, rises, OK)
