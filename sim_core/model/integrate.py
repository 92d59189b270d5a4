"""Stance phase: a compiled DOP853 integrator with exact event location (docs/model.md §2, §3).

The stance is integrated in polar coordinates about the foot (paper eq. 3,
:mod:`sim_core.model.stance_equations`) with the 8th-order Dormand–Prince method and scipy's
step-size control; the step itself (:mod:`sim_core.model._dop853`) is generated from scipy's
tableau, so both integrators share one table. Events are coordinate thresholds: lift-off
``zeta = 1``, collapse ``zeta = COLLAPSE_ZETA``, slip ``|psi| = atan(mu)``, the stance time
cap. When a step crosses one, the step is redone with Hénon's trick — the crossed coordinate
becomes the independent variable, so the integrator lands exactly on the threshold at full
order instead of bisecting an interpolant.

Kernels here never raise: they return a status from :mod:`sim_core.model.failures`. States are
tuples laid out as in :mod:`sim_core.model.stance_equations` (re-exported here); tuples rather
than arrays keep the state in registers and the kernel free of allocations.
"""

from __future__ import annotations

import math

from sim_core._jit import kernel
from sim_core.model._dop853 import dop853_step
from sim_core.model.failures import COLLAPSE, INVALID_STATE, NO_LIFTOFF, OK, SLIP
from sim_core.model.stance_equations import (
    COS_PSI,
    PSI,
    PSI_DOT,
    SIN_PSI,
    STATE_SIZE,
    TIME,
    ZETA,
    ZETA_DOT,
    rates,
    replace_item,
)

__all__ = [
    "ATOL",
    "COLLAPSE_ZETA",
    "COS_PSI",
    "PSI",
    "PSI_DOT",
    "RTOL",
    "SIN_PSI",
    "STANCE_TIME_CAP",
    "STATE_SIZE",
    "TIME",
    "ZETA",
    "ZETA_DOT",
    "stance",
    "stance_in_cone",
]

RTOL = 1e-11  # 10x tighter than the bench baseline; docs/simulation.md gives the measured accuracy
ATOL = 1e-11
COLLAPSE_ZETA = 1e-3  # [l0]: the body has effectively reached the foot
STANCE_TIME_CAP = 10.0  # [sqrt(l0/g)]: about 25 natural stances; beyond it the spring never re-extends
MAX_STEPS = 100_000
FIRST_STEP = 0.3  # [1/sqrt(1 + alpha) of sqrt(l0/g)]: a fraction of the spring's period

_SAFETY = 0.9
_MIN_FACTOR = 0.2
_MAX_FACTOR = 10.0
_MIN_STEP = 1e-14


@kernel
def _eighth_root(x):
    """``x ** (1/8)`` for the step-size controller (order 8): three square roots beat ``pow``."""
    return math.sqrt(math.sqrt(math.sqrt(x)))


@kernel
def _accepted_step(state, rate, h, limit, direction, alpha, c_zeta, c_psi, independent):
    """Try steps (magnitude ``h``, at most ``limit``) until one is accepted.

    Returns ``(taken, next_h, new_state, new_rate)``; ``taken < 0`` when the step size underflows.
    """
    rejected = False
    while True:
        step = min(h, limit)
        new_state, new_rate, error = dop853_step(
            state, rate, direction * step, alpha, c_zeta, c_psi, independent, RTOL, ATOL
        )
        if error < 1.0:
            factor = _MAX_FACTOR if error == 0.0 else min(_MAX_FACTOR, _SAFETY / _eighth_root(error))
            if rejected:
                factor = min(1.0, factor)
            return step, step * factor, new_state, new_rate
        rejected = True
        # NaN errors land here too: max() then keeps the minimum factor and the step shrinks.
        h = step * max(_MIN_FACTOR, _SAFETY / _eighth_root(error))
        if h < _MIN_STEP:
            return -1.0, 0.0, new_state, new_rate


@kernel
def _land(state, independent, target, alpha, c_zeta, c_psi):
    """Integrate from ``state`` until coordinate ``independent`` equals ``target`` exactly.

    Used on the step that crossed an event. Returns ``(landed, state)``; ``landed`` is False if
    the integrator could not get there (e.g. the coordinate's rate vanishes at a grazing crossing).
    """
    remaining = target - state[independent]
    direction = 1.0 if remaining >= 0.0 else -1.0
    h = abs(remaining)
    for _ in range(1000):
        remaining = abs(target - state[independent])
        if remaining <= 0.0:
            break
        rate = rates(state, alpha, c_zeta, c_psi, independent)
        if not math.isfinite(rate[ZETA] + rate[PSI] + rate[TIME]):
            return False, state
        taken, h, state, _ = _accepted_step(state, rate, h, remaining, direction, alpha, c_zeta, c_psi, independent)
        if taken < 0.0:
            return False, state
        if taken >= remaining:
            break
    return True, replace_item(state, independent, target)


@kernel
def _record_row(record, row, state):
    if row < record.shape[0]:
        _store(record[row], state)
        return row + 1
    return row


@kernel
def stance(zeta0, psi0, zeta_dot0, psi_dot0, alpha, c_zeta, c_psi, mu, final, record):
    """Integrate one stance from touchdown to its end, the foot on a vertical wall.

    Args:
        zeta0, psi0, zeta_dot0, psi_dot0: touchdown state in polar coordinates about the foot
            [l0, rad, l0/sqrt(l0/g), rad/sqrt(l0/g)].
        alpha, c_zeta, c_psi, mu: nondimensional model parameters (docs/model.md §1).
        final: output, shape (STATE_SIZE,): the state at the end of stance (time in TIME).
        record: output, shape (K, STATE_SIZE): touchdown, every accepted step and the end state
            are written while rows last (K = 0 records nothing).

    Returns:
        ``(status, rows_recorded)``; status OK means lift-off (``zeta = 1``, ``zeta_dot > 0``).
    """
    psi_limit = math.atan(mu)  # |tan psi| > mu  <=>  |psi| > atan(mu) on (-pi/2, pi/2)
    return stance_in_cone(zeta0, psi0, zeta_dot0, psi_dot0, alpha, c_zeta, c_psi, -psi_limit, psi_limit, final, record)


@kernel
def stance_in_cone(zeta0, psi0, zeta_dot0, psi_dot0, alpha, c_zeta, c_psi, psi_low, psi_high, final, record):
    """:func:`stance` on a foothold whose friction cone is ``psi_low < psi < psi_high`` [rad]: on
    a segment of inclination ``beta`` with friction ``mu``, ``beta -/+ atan(mu)`` (docs/model.md
    §8); a vertical wall's cone is ``-/+ atan(mu)``, the same comparisons as ``|psi| >= atan(mu)``."""
    state = (zeta0, psi0, zeta_dot0, psi_dot0, math.cos(psi0), math.sin(psi0), 0.0)
    _store(final, state)
    rows = _record_row(record, 0, state)
    if not (math.isfinite(zeta0 + psi0 + zeta_dot0 + psi_dot0) and 0.0 < zeta0 < 1.0):
        return INVALID_STATE, rows
    if psi0 >= psi_high or psi0 <= psi_low:
        return SLIP, rows
    if zeta0 <= COLLAPSE_ZETA:  # touched down already collapsed: no step would start inside
        return COLLAPSE, rows
    rate = rates(state, alpha, c_zeta, c_psi, TIME)
    h = FIRST_STEP / math.sqrt(1.0 + alpha)
    for _ in range(MAX_STEPS):
        taken, h, new_state, new_rate = _accepted_step(state, rate, h, math.inf, 1.0, alpha, c_zeta, c_psi, TIME)
        if taken < 0.0:
            return INVALID_STATE, rows
        new_zeta = new_state[ZETA]
        new_psi = new_state[PSI]
        crossed_liftoff = new_zeta >= 1.0
        crossed_collapse = new_zeta <= COLLAPSE_ZETA
        crossed_slip = new_psi >= psi_high or new_psi <= psi_low
        crossed_cap = new_state[TIME] >= STANCE_TIME_CAP
        if not (crossed_liftoff or crossed_collapse or crossed_slip or crossed_cap):
            if not math.isfinite(new_zeta + new_psi + new_state[ZETA_DOT] + new_state[PSI_DOT]):
                return INVALID_STATE, rows
            state = new_state
            rate = new_rate
            rows = _record_row(record, rows, state)
            continue
        # A step crossed one or more event surfaces: land on each, keep the earliest.
        status = INVALID_STATE
        best = state
        for event in range(4):
            if event == 0 and crossed_liftoff:
                independent, target, code = ZETA, 1.0, OK
            elif event == 1 and crossed_collapse:
                independent, target, code = ZETA, COLLAPSE_ZETA, COLLAPSE
            elif event == 2 and crossed_slip:
                independent, target, code = PSI, psi_high if new_psi >= psi_high else psi_low, SLIP
            elif event == 3 and crossed_cap:
                independent, target, code = TIME, STANCE_TIME_CAP, NO_LIFTOFF
            else:
                continue
            landed, end = _land(state, independent, target, alpha, c_zeta, c_psi)
            # A landing behind the step's start would mean the surface was crossed before it.
            landed = landed and end[TIME] >= state[TIME]
            if landed and (status == INVALID_STATE or end[TIME] < best[TIME]):
                best = end
                status = code
        if status == INVALID_STATE:
            return INVALID_STATE, rows
        _store(final, best)
        rows = _record_row(record, rows, best)
        return status, rows
    return INVALID_STATE, rows


@kernel
def _store(out, state):
    for i in range(STATE_SIZE):
        out[i] = state[i]
