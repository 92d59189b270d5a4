"""The model's prediction of tracked touchdowns, jump by jump: what calibration fits (docs/calibration.md).

A tracked run gives, per touchdown, the section state and foot height a detector measured, the
controls the PC commanded for that touchdown and the body's pitch. The robot does not touch down
with the commanded controls: its servos add per-leg offsets (:class:`~sim_core.model.controls.LegOffsets`)
and its pitch turns the leg (``+pitch`` on the left wall, ``-pitch`` on the right, as
:mod:`sim_core.model.noise`). So the leg meets the wall ``a = zeta0 cos psi0`` [l0] from it (realised),
while the detector (backend.robot.touchdown), which knows the pitch but not the offsets, finds the
crossing of the line ``c`` of the commanded leg turned by the pitch by extrapolating the flight:
its state and foot height are the ballistic flight's at ``c``, a time ``(a - c) / |xdot|`` after
the real touchdown (nondimensional time, gravity 1). This module maps
a measured touchdown back to the real one, runs one jump of the Poincaré map
(:func:`sim_core.model.stride.jump`) and maps the next real touchdown forward to what the detector
will report — so model and measurement are compared as the same quantity.

Units: states in ``sqrt(g l0)``, heights in ``l0``, angles in radians; walls as in
:mod:`sim_core.model.walls`.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._jit import kernel
from sim_core.calibration.touchdown_series import PSI0_ERROR, ZETA0_ERROR, Pairs
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.params import ModelRecord
from sim_core.model.stride import jump

# Inputs :func:`sensitivities` differentiates by: (table, column) and the finite-difference step.
INPUTS = (("before", 0, 1e-5), ("before", 1, 1e-5), ("before", PSI0_ERROR, 1e-6), ("before", ZETA0_ERROR, 1e-6),
          ("after", PSI0_ERROR, 1e-6), ("after", ZETA0_ERROR, 1e-6))  # fmt: skip

# Columns of the per-pair outputs of :func:`predict_pairs`.
XDOT, YDOT, RISE = 0, 1, 2


@kernel
def _realised(psi0, zeta0, right_leg, pitch, psi0_offsets, zeta0_offsets):
    side = 1 if right_leg else 0
    turned = psi0 + (-pitch if right_leg else pitch) + psi0_offsets[side]
    return turned, zeta0 + zeta0_offsets[side]


@kernel
def _detection_shift(xdot, psi0, zeta0, psi0_commanded, zeta0_commanded):
    """Time [sqrt(l0/g)] from the real touchdown to the detector's crossing of the commanded line."""
    real = zeta0 * math.cos(psi0)
    commanded = zeta0_commanded * math.cos(psi0_commanded)
    return (real - commanded) / abs(xdot)


@kernel
def _foot_shift(ydot, shift, psi0, zeta0, psi0_commanded, zeta0_commanded):
    """Detected minus real foot height [l0]: the flight carried on ``shift``, the commanded leg subtracted."""
    body = ydot * shift - 0.5 * shift * shift
    return body - zeta0_commanded * math.sin(psi0_commanded) + zeta0 * math.sin(psi0)


@kernel
def predict_pairs(before, after, model, psi0_offsets, zeta0_offsets, out):
    """The detected touchdown ``k + 1`` the model predicts from each measured touchdown ``k``.

    Args:
        before, after: :class:`Pairs` columns; only ``after``'s controls, leg and pitch are read.
        model: the model's record (:meth:`sim_core.model.params.ModelParams.record`).
        psi0_offsets [rad], zeta0_offsets [l0]: shape (2,), left and right leg.
        out: output (pairs, 3): predicted ``xdot, ydot`` and rise [l0]; NaN where the jump failed.

    Returns the number of failed jumps.
    """
    no_record = np.empty((0, STATE_SIZE))
    no_offsets = np.zeros(2)
    failed = 0
    for i in range(before.shape[0]):
        psi_c, zeta_c, right, pitch = before[i, 3], before[i, 4], before[i, 5] > 0.5, before[i, 6]
        psi_n, zeta_n, right_n, pitch_n = after[i, 3], after[i, 4], after[i, 5] > 0.5, after[i, 6]
        psi0, zeta0 = _realised(psi_c, zeta_c, right, pitch, psi0_offsets, zeta0_offsets)
        next_psi0, next_zeta0 = _realised(psi_n, zeta_n, right_n, pitch_n, psi0_offsets, zeta0_offsets)
        psi0, zeta0 = psi0 + before[i, PSI0_ERROR], zeta0 + before[i, ZETA0_ERROR]
        next_psi0, next_zeta0 = next_psi0 + after[i, PSI0_ERROR], next_zeta0 + after[i, ZETA0_ERROR]
        # The detector's leg: the commanded one turned by the pitch (no offsets: it cannot know them).
        psi_c, zeta_c = _realised(psi_c, zeta_c, right, pitch, no_offsets, no_offsets)
        psi_n, zeta_n = _realised(psi_n, zeta_n, right_n, pitch_n, no_offsets, no_offsets)
        xdot = before[i, 0]
        shift = _detection_shift(xdot, psi0, zeta0, psi_c, zeta_c)
        ydot = before[i, 1] + shift  # back to the real touchdown
        status, next_xdot, next_ydot, rise, _, _, _ = jump(
            xdot, ydot, psi0, zeta0, next_psi0, next_zeta0, model, no_record
        )
        if status != OK or not (next_xdot < 0.0):
            out[i, :] = math.nan
            failed += 1
            continue
        next_shift = _detection_shift(next_xdot, next_psi0, next_zeta0, psi_n, zeta_n)
        out[i, XDOT] = next_xdot
        out[i, YDOT] = next_ydot - next_shift
        out[i, RISE] = (
            rise
            + _foot_shift(next_ydot, next_shift, next_psi0, next_zeta0, psi_n, zeta_n)
            - _foot_shift(ydot, shift, psi0, zeta0, psi_c, zeta_c)
        )
    return failed


def sensitivities(pairs: Pairs, model: ModelRecord, psi0_offsets: np.ndarray, zeta0_offsets: np.ndarray) -> np.ndarray:
    """Shape (pairs, 3, 6): how each predicted ``(xdot, ydot, rise)`` moves with the inputs of
    :data:`INPUTS` — the measured state ``(xdot, ydot)`` of touchdown ``k`` and the two legs'
    ``(psi0 [rad], zeta0 [l0])`` errors — by central differences, on ``model``
    (:meth:`sim_core.model.params.ModelParams.record`); NaN where a jump fails."""
    result = np.empty((len(pairs), 3, len(INPUTS)))
    plus, minus = np.empty((len(pairs), 3)), np.empty((len(pairs), 3))
    for j, (table, column, step) in enumerate(INPUTS):
        for sign, out in ((1.0, plus), (-1.0, minus)):
            tables = {"before": pairs.before.copy(), "after": pairs.after.copy()}
            tables[table][:, column] += sign * step
            predict_pairs(tables["before"], tables["after"], model, psi0_offsets, zeta0_offsets, out)
        result[:, :, j] = (plus - minus) / (2.0 * step)
    return result
