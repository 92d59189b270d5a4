"""Stance phase: a compiled DOP853 integrator with exact event location (model.md §2, §3).

The stance is integrated in polar coordinates about the foot (paper eq. 3) with the
8th-order Dormand–Prince method and scipy's step-size control (coefficients are scipy's,
imported so that both integrators share one table). Events are coordinate thresholds:
lift-off ``zeta = 1``, collapse ``zeta = COLLAPSE_ZETA``, slip ``|psi| = atan(mu)``, the
stance time cap. When a step crosses one, the step is redone with Hénon's trick — the
crossed coordinate becomes the independent variable, so the integrator lands exactly on
the threshold at full order instead of bisecting an interpolant.

Kernels here never raise: they return a status from :mod:`sim_core.failures`. The
extended state is ``(zeta, psi, zeta_dot, psi_dot, cos psi, sin psi, t)``, indexed by the
names below: carrying ``cos psi`` and ``sin psi`` (with ``d cos psi/dt = -sin psi psi_dot``)
takes the trigonometry out of the twelve right-hand-side evaluations per step, which made
the kernel 1.6x faster; ``t`` is there so Hénon's trick can integrate it as a dependent
variable.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _dop853

from sim_core._jit import kernel
from sim_core.failures import COLLAPSE, INVALID_STATE, NO_LIFTOFF, OK, SLIP

ZETA = 0
PSI = 1
ZETA_DOT = 2
PSI_DOT = 3
COS_PSI = 4
SIN_PSI = 5
TIME = 6
STATE_SIZE = 7

RTOL = 1e-12
ATOL = 1e-12
COLLAPSE_ZETA = 1e-3  # [l0]: the body has effectively reached the foot
STANCE_TIME_CAP = 10.0  # [sqrt(l0/g)]: about 25 natural stances; beyond it the spring never re-extends
MAX_STEPS = 100_000
FIRST_STEP = 0.15  # [1/sqrt(1 + alpha) of sqrt(l0/g)]: a fraction of the spring's period

_N_STAGES = _dop853.N_STAGES
_A = np.ascontiguousarray(_dop853.A[:_N_STAGES, :_N_STAGES])
_B = np.ascontiguousarray(_dop853.B)
_E3 = np.ascontiguousarray(_dop853.E3)
_E5 = np.ascontiguousarray(_dop853.E5)
_SAFETY = 0.9
_MIN_FACTOR = 0.2
_MAX_FACTOR = 10.0
_ERROR_EXPONENT = -1.0 / 8.0
_MIN_STEP = 1e-14

# Rows of the per-call workspace.
_W_STAGES = 0  # _N_STAGES + 1 rows of stage derivatives
_W_STAGE_STATE = _N_STAGES + 1
_W_STATE = _N_STAGES + 2
_W_DERIVATIVE = _N_STAGES + 3
_W_NEW_STATE = _N_STAGES + 4
_W_NEW_DERIVATIVE = _N_STAGES + 5
_W_LANDED = _N_STAGES + 6
_W_LANDED_DERIVATIVE = _N_STAGES + 7
_W_BEST = _N_STAGES + 8
_W_ROWS = _N_STAGES + 9


@kernel
def _derivative(state, alpha, c_zeta, c_psi, independent, out):
    """Stance equations of motion (paper eq. 3), with respect to ``state[independent]``."""
    zeta = state[ZETA]
    zeta_dot = state[ZETA_DOT]
    psi_dot = state[PSI_DOT]
    cos_psi = state[COS_PSI]
    sin_psi = state[SIN_PSI]
    out[ZETA] = zeta_dot
    out[PSI] = psi_dot
    out[ZETA_DOT] = alpha * (1.0 - zeta) + zeta * psi_dot * psi_dot - sin_psi - c_zeta * zeta_dot
    out[PSI_DOT] = -(cos_psi + 2.0 * zeta_dot * psi_dot) / zeta - c_psi * psi_dot
    out[COS_PSI] = -sin_psi * psi_dot
    out[SIN_PSI] = cos_psi * psi_dot
    out[TIME] = 1.0
    if independent != TIME:
        # Hénon's trick: d/ds = (d/dt) / (ds/dt) with s = state[independent].
        scale = 1.0 / out[independent]
        for i in range(STATE_SIZE):
            out[i] *= scale
        out[independent] = 1.0


@kernel
def _dop853_step(state, derivative, h, alpha, c_zeta, c_psi, independent, work):
    """One DOP853 step of size ``h``; result in the workspace, returns the error norm (<1 = accept)."""
    stages = work[_W_STAGES : _N_STAGES + 1]
    stage_state = work[_W_STAGE_STATE]
    new_state = work[_W_NEW_STATE]
    new_derivative = work[_W_NEW_DERIVATIVE]
    for i in range(STATE_SIZE):
        stages[0, i] = derivative[i]
    for s in range(1, _N_STAGES):
        for i in range(STATE_SIZE):
            acc = 0.0
            for j in range(s):
                acc += _A[s, j] * stages[j, i]
            stage_state[i] = state[i] + h * acc
        _derivative(stage_state, alpha, c_zeta, c_psi, independent, stages[s])
    for i in range(STATE_SIZE):
        acc = 0.0
        for j in range(_N_STAGES):
            acc += _B[j] * stages[j, i]
        new_state[i] = state[i] + h * acc
    _derivative(new_state, alpha, c_zeta, c_psi, independent, new_derivative)
    for i in range(STATE_SIZE):
        stages[_N_STAGES, i] = new_derivative[i]
    # Error estimate of scipy's DOP853 (_estimate_error_norm): blended 5th/3rd-order estimators.
    err5 = 0.0
    err3 = 0.0
    for i in range(STATE_SIZE):
        scale = ATOL + RTOL * max(abs(state[i]), abs(new_state[i]))
        e5 = 0.0
        e3 = 0.0
        for j in range(_N_STAGES + 1):
            e5 += _E5[j] * stages[j, i]
            e3 += _E3[j] * stages[j, i]
        err5 += (e5 / scale) ** 2
        err3 += (e3 / scale) ** 2
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    return abs(h) * err5 / math.sqrt((err5 + 0.01 * err3) * STATE_SIZE)


@kernel
def _accepted_step(state, derivative, h, limit, direction, alpha, c_zeta, c_psi, independent, work):
    """Try steps (magnitude ``h``, at most ``limit``) until one is accepted.

    Returns ``(taken, next_h)``; ``taken < 0`` when the step size underflows. The accepted
    state and derivative are in the workspace rows _W_NEW_STATE / _W_NEW_DERIVATIVE.
    """
    rejected = False
    while True:
        step = min(h, limit)
        error = _dop853_step(state, derivative, direction * step, alpha, c_zeta, c_psi, independent, work)
        if error < 1.0:
            factor = _MAX_FACTOR if error == 0.0 else min(_MAX_FACTOR, _SAFETY * error**_ERROR_EXPONENT)
            if rejected:
                factor = min(1.0, factor)
            return step, step * factor
        rejected = True
        # NaN errors land here too: max() then keeps the minimum factor and the step shrinks.
        h = step * max(_MIN_FACTOR, _SAFETY * error**_ERROR_EXPONENT)
        if h < _MIN_STEP:
            return -1.0, 0.0


@kernel
def _land(state, independent, target, alpha, c_zeta, c_psi, work, out):
    """Integrate from ``state`` until coordinate ``independent`` equals ``target`` exactly.

    Used on the step that crossed an event; returns False if the integrator could not get there
    (e.g. the coordinate's rate vanishes at a grazing crossing).
    """
    landed = work[_W_LANDED]
    derivative = work[_W_LANDED_DERIVATIVE]
    for i in range(STATE_SIZE):
        landed[i] = state[i]
    remaining = target - landed[independent]
    direction = 1.0 if remaining >= 0.0 else -1.0
    h = abs(remaining)
    for _ in range(1000):
        remaining = abs(target - landed[independent])
        if remaining <= 0.0:
            break
        _derivative(landed, alpha, c_zeta, c_psi, independent, derivative)
        if not math.isfinite(derivative[ZETA] + derivative[PSI] + derivative[TIME]):
            return False
        taken, h = _accepted_step(landed, derivative, h, remaining, direction, alpha, c_zeta, c_psi, independent, work)
        if taken < 0.0:
            return False
        for i in range(STATE_SIZE):
            landed[i] = work[_W_NEW_STATE, i]
        if taken >= remaining:
            break
    landed[independent] = target
    for i in range(STATE_SIZE):
        out[i] = landed[i]
    return True


@kernel
def _record_row(record, row, state):
    if row < record.shape[0]:
        for i in range(STATE_SIZE):
            record[row, i] = state[i]
        return row + 1
    return row


@kernel
def stance(zeta0, psi0, zeta_dot0, psi_dot0, alpha, c_zeta, c_psi, mu, final, record):
    """Integrate one stance from touchdown to its end.

    Args:
        zeta0, psi0, zeta_dot0, psi_dot0: touchdown state in polar coordinates about the foot
            [l0, rad, l0/sqrt(l0/g), rad/sqrt(l0/g)].
        alpha, c_zeta, c_psi, mu: nondimensional model parameters (model.md §1).
        final: output, shape (STATE_SIZE,): the state at the end of stance (time in TIME).
        record: output, shape (K, STATE_SIZE): touchdown, every accepted step and the end state
            are written while rows last (K = 0 records nothing).

    Returns:
        ``(status, rows_recorded)``; status OK means lift-off (``zeta = 1``, ``zeta_dot > 0``).
    """
    work = np.empty((_W_ROWS, STATE_SIZE))
    state = work[_W_STATE]
    derivative = work[_W_DERIVATIVE]
    best = work[_W_BEST]
    state[ZETA] = zeta0
    state[PSI] = psi0
    state[ZETA_DOT] = zeta_dot0
    state[PSI_DOT] = psi_dot0
    state[COS_PSI] = math.cos(psi0)
    state[SIN_PSI] = math.sin(psi0)
    state[TIME] = 0.0
    for i in range(STATE_SIZE):
        final[i] = state[i]
    rows = _record_row(record, 0, state)
    if not (math.isfinite(zeta0 + psi0 + zeta_dot0 + psi_dot0) and 0.0 < zeta0 < 1.0):
        return INVALID_STATE, rows
    psi_limit = math.atan(mu)  # |tan psi| > mu  <=>  |psi| > atan(mu) on (-pi/2, pi/2)
    if abs(psi0) >= psi_limit:
        return SLIP, rows
    _derivative(state, alpha, c_zeta, c_psi, TIME, derivative)
    h = FIRST_STEP / math.sqrt(1.0 + alpha)
    for _ in range(MAX_STEPS):
        taken, h = _accepted_step(state, derivative, h, math.inf, 1.0, alpha, c_zeta, c_psi, TIME, work)
        if taken < 0.0:
            return INVALID_STATE, rows
        new_zeta = work[_W_NEW_STATE, ZETA]
        new_psi = work[_W_NEW_STATE, PSI]
        new_time = work[_W_NEW_STATE, TIME]
        crossed_liftoff = new_zeta >= 1.0
        crossed_collapse = new_zeta <= COLLAPSE_ZETA
        crossed_slip = abs(new_psi) >= psi_limit
        crossed_cap = new_time >= STANCE_TIME_CAP
        if not (crossed_liftoff or crossed_collapse or crossed_slip or crossed_cap):
            if not math.isfinite(new_zeta + new_psi + work[_W_NEW_STATE, ZETA_DOT] + work[_W_NEW_STATE, PSI_DOT]):
                return INVALID_STATE, rows
            for i in range(STATE_SIZE):
                state[i] = work[_W_NEW_STATE, i]
                derivative[i] = work[_W_NEW_DERIVATIVE, i]
            rows = _record_row(record, rows, state)
            continue
        # A step crossed one or more event surfaces: land on each, keep the earliest.
        status = INVALID_STATE
        best_time = math.inf
        for event in range(4):
            if event == 0 and crossed_liftoff:
                independent, target, code = ZETA, 1.0, OK
            elif event == 1 and crossed_collapse:
                independent, target, code = ZETA, COLLAPSE_ZETA, COLLAPSE
            elif event == 2 and crossed_slip:
                independent, target, code = PSI, math.copysign(psi_limit, new_psi), SLIP
            elif event == 3 and crossed_cap:
                independent, target, code = TIME, STANCE_TIME_CAP, NO_LIFTOFF
            else:
                continue
            landed = _land(state, independent, target, alpha, c_zeta, c_psi, work, final)
            if landed and final[TIME] < best_time:
                best_time = final[TIME]
                status = code
                for i in range(STATE_SIZE):
                    best[i] = final[i]
        if status == INVALID_STATE:
            return INVALID_STATE, rows
        for i in range(STATE_SIZE):
            final[i] = best[i]
        rows = _record_row(record, rows, final)
        return status, rows
    return INVALID_STATE, rows
