"""An LQR designed on the model's own return map: linearised about a gait of jumping in place, with
the robot's one jump of delay in its state (docs/analyses.md, "Controllers").

At touchdown ``k`` the robot has already touched down with controls ``u_k`` and chooses ``u_{k+1}``,
which sets where the coming flight ends. The map (:func:`sim_core.model.stride.jump`) takes the section
state ``s_k`` and both controls to ``s_{k+1}`` and the body's rise ``h_{k+1} - h_k``; linearised
about the gait ``(s*, u*)`` by central differences:

    δs_{k+1} = A δs_k + B1 δu_k + B2 δu_{k+1}
    e_{k+1}  = e_k + C δs_k + D1 δu_k + D2 δu_{k+1}        (e: the height error [l0])

so ``x_k = (δs_k, e_k, δu_k)`` evolves as ``x_{k+1} = Φ x_k + Γ δu_{k+1}``, and the gain ``K`` of
``δu_{k+1} = -K x_k`` solves the discrete algebraic Riccati equation (scipy) for the weights
``Q = diag(q_state, q_state, q_height, 0, 0)``, ``R = diag(r_psi0, r_zeta0)``. A calibrated preset
gives its own gait, its own map and so its own controller.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solve_discrete_are

from sim_core.control.laws import Lqr
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelParams
from sim_core.model.presets import START_GUESS
from sim_core.model.stride import jump
from sim_core.model.validation import ParameterError
from sim_core.section.gait_search import gait_of

STEP = 1e-6  # central differences' step [sqrt(g l0), rad, l0]
# Weights (per l0² of height error, per (sqrt(g l0))² of state, per rad² and per l0² of control):
# chosen on the benchmark (docs/analyses.md): the height first, the legs' moves cheap.
Q_HEIGHT, Q_STATE, R_PSI0, R_ZETA0 = 1.0, 0.05, 4.0, 8.0


def linearised_map(model: ModelParams, state, psi0: float, zeta0: float) -> np.ndarray:
    """The 3 x 6 Jacobian of ``(s_{k+1}, rise of the body)`` in ``(s_k, u_k, u_{k+1})`` at the gait
    ``state`` with controls ``(psi0 [rad], zeta0)`` on every jump."""
    point = np.array([state[0], state[1], psi0, zeta0, psi0, zeta0])
    record = np.empty((0, STATE_SIZE))
    parameters = model.record()

    def outcome(values: np.ndarray) -> np.ndarray:
        xdot, ydot, psi0_k, zeta0_k, psi0_next, zeta0_next = values
        status, next_xdot, next_ydot, rise, *_ = jump(
            xdot, ydot, psi0_k, zeta0_k, psi0_next, zeta0_next, parameters, record
        )
        if status != OK:
            raise ParameterError("psi0_deg", "the gait fails within a linearisation step: no LQR about it")
        body_rise = rise + zeta0_next * math.sin(psi0_next) - zeta0_k * math.sin(psi0_k)
        return np.array([next_xdot, next_ydot, body_rise])

    jacobian = np.empty((3, 6))
    for column in range(6):
        step = np.zeros(6)
        step[column] = STEP
        jacobian[:, column] = (outcome(point + step) - outcome(point - step)) / (2 * STEP)
    return jacobian


def delayed_system(jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Φ, Γ)`` of ``x = (δs, e, δu)`` with the next controls as the input."""
    a, b1, b2 = jacobian[:2, :2], jacobian[:2, 2:4], jacobian[:2, 4:]
    c, d1, d2 = jacobian[2, :2], jacobian[2, 2:4], jacobian[2, 4:]
    phi = np.zeros((5, 5))
    phi[:2, :2], phi[:2, 3:] = a, b1
    phi[2, :2], phi[2, 2], phi[2, 3:] = c, 1.0, d1
    gamma = np.zeros((5, 2))
    gamma[:2], gamma[2], gamma[3:] = b2, d2, np.eye(2)
    return phi, gamma


def design_lqr(
    model: ModelParams,
    target: float,
    psi0_deg: float,
    zeta0_hover: float,
    *,
    error_clip: float = 0.4,
    state_clip: float = 0.15,
    weights: tuple[float, float, float, float] = (Q_HEIGHT, Q_STATE, R_PSI0, R_ZETA0),
    zeta0_range: tuple[float, float] = (0.80, 0.98),
    guess=START_GUESS,
) -> Lqr:
    """The LQR holding ``target`` [l0] about the gait of jumping in place at ``psi0_deg`` with
    ``zeta0_hover`` (e.g. :func:`sim_core.basins.sweep.find_in_place_zeta0`); ``weights`` are
    ``(q_height, q_state, r_psi0, r_zeta0)``."""
    psi0 = math.radians(psi0_deg)
    gait = gait_of(model, ControlSchedule.of(LegControl(psi0, zeta0_hover)), guess=guess)
    phi, gamma = delayed_system(linearised_map(model, gait.state, psi0, zeta0_hover))
    q_height, q_state, r_psi0, r_zeta0 = weights
    q = np.diag([q_state, q_state, q_height, 0.0, 0.0])
    r = np.diag([r_psi0, r_zeta0])
    riccati = solve_discrete_are(phi, gamma, q, r)
    gain = np.linalg.solve(r + gamma.T @ riccati @ gamma, gamma.T @ riccati @ phi)
    return Lqr(target=target, psi0_deg=psi0_deg, zeta0=zeta0_hover, state=(float(gait.state[0]), float(gait.state[1])),
               gain=tuple(float(value) for value in gain.ravel()), error_clip=error_clip, state_clip=state_clip,
               zeta0_range=zeta0_range)  # fmt: skip
