"""The model's prediction of tracked touchdowns, jump by jump: what calibration fits (docs/calibration.md).

A tracked run gives, per touchdown, the section state and foot height a detector measured, the
controls the PC commanded for that touchdown and the body's pitch. The robot does not touch down
with the commanded controls: its servos add per-leg offsets (:class:`~sim_core.controls.LegOffsets`)
and its pitch turns the leg (``+pitch`` on the left wall, ``-pitch`` on the right, as
:mod:`sim_core.noise`). So the leg meets the wall ``a = zeta0 cos psi0`` [l0] from it (realised),
while the detector (backend.robot.touchdown), which knows the pitch but not the offsets, finds the
crossing of the line ``c`` of the commanded leg turned by the pitch by extrapolating the flight:
its state and foot height are the ballistic flight's at ``c``, a time ``(a - c) / |xdot|`` after
the real touchdown (nondimensional time, gravity 1). This module maps
a measured touchdown back to the real one, runs one jump of the Poincaré map
(:func:`sim_core.stride.jump`) and maps the next real touchdown forward to what the detector
will report — so model and measurement are compared as the same quantity.

Units: states in ``sqrt(g l0)``, heights in ``l0``, angles in radians; walls as in
:mod:`sim_core.walls`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core._jit import kernel
from sim_core.failures import OK
from sim_core.integrate import STATE_SIZE
from sim_core.stride import jump
from sim_core.validation import ParameterError

# Tracker frames whose pitch is a touchdown's: the 50 ms before the detected crossing [s], the end of
# the flight, whose pitch the leg reached with (the body's pitch steps at lift-off).
PITCH_WINDOW = (-0.05, 0.0)

COLUMNS = 9  # of Pairs.before and .after
PSI0_ERROR, ZETA0_ERROR = 7, 8
# Inputs :func:`sensitivities` differentiates by: (table, column) and the finite-difference step.
INPUTS = (("before", 0, 1e-5), ("before", 1, 1e-5), ("before", PSI0_ERROR, 1e-6), ("before", ZETA0_ERROR, 1e-6),
          ("after", PSI0_ERROR, 1e-6), ("after", ZETA0_ERROR, 1e-6))  # fmt: skip

# Columns of the per-pair outputs of :func:`predict_pairs`.
XDOT, YDOT, RISE = 0, 1, 2
CHANNELS = ("xdot", "ydot", "rise")
CHANNEL_UNITS = {"xdot": "sqrt(g l0)", "ydot": "sqrt(g l0)", "rise": "l0"}


@dataclass(frozen=True)
class TouchdownSeries:
    """One run's detected touchdowns, in order (nondimensional, flipped to the left wall).

    Attributes:
        state: shape (n, 2), the measured section states ``(xdot, ydot)``.
        foot_height: shape (n,), the measured foot heights [l0].
        commanded: shape (n, 2), the commanded ``(psi0 [rad], zeta0 [l0])`` of each touchdown's leg.
        right_leg: shape (n,), whether the touchdown is on the right wall (its leg the right one).
        pitch: shape (n,), the body's pitch at the touchdown [rad]; 0 where the tracker gave none.
        consecutive: shape (n - 1,), whether touchdown ``k + 1`` is the jump after ``k`` (none missed).
    """

    state: np.ndarray
    foot_height: np.ndarray
    commanded: np.ndarray
    right_leg: np.ndarray
    pitch: np.ndarray
    consecutive: np.ndarray

    def __post_init__(self) -> None:
        n = self.state.shape[0]
        shapes = {"state": (n, 2), "foot_height": (n,), "commanded": (n, 2), "right_leg": (n,), "pitch": (n,),
                  "consecutive": (max(n - 1, 0),)}  # fmt: skip
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise ParameterError(name, f"must have shape {shape}, got {getattr(self, name).shape}")

    @classmethod
    def of(cls, *, state, foot_height, commanded, right_leg, pitch=None) -> TouchdownSeries:
        """A series from sequences; a pair counts as consecutive when its walls alternate."""
        right = np.asarray(right_leg, dtype=bool)
        pitches = np.zeros(right.shape) if pitch is None else np.nan_to_num(np.asarray(pitch, dtype=float))
        return cls(
            state=np.asarray(state, dtype=float).reshape(-1, 2),
            foot_height=np.asarray(foot_height, dtype=float),
            commanded=np.asarray(commanded, dtype=float).reshape(-1, 2),
            right_leg=right,
            pitch=pitches,
            consecutive=right[1:] != right[:-1],
        )

    @property
    def pairs(self) -> int:
        return int(np.count_nonzero(self.consecutive))


@dataclass(frozen=True)
class Pairs:
    """Consecutive touchdown pairs ``k -> k + 1`` of any number of runs, as the kernel takes them.

    ``before`` and ``after`` hold, per pair, columns ``xdot, ydot, foot_height, psi0_commanded,
    zeta0_commanded, right_leg (0/1), pitch, psi0_error, zeta0_error`` of touchdown ``k`` and
    ``k + 1``; the errors (0 as measured) are what the leg realised beyond the commanded, offset and
    pitch — the per-jump control noise — and let :func:`sensitivities` ask what it would change.
    """

    before: np.ndarray
    after: np.ndarray

    @classmethod
    def of(cls, series: list[TouchdownSeries]) -> Pairs:
        rows = []
        for run in series:
            errors = np.zeros((run.right_leg.size, 2))
            table = np.column_stack([run.state, run.foot_height, run.commanded, run.right_leg, run.pitch, errors])
            keep = np.flatnonzero(run.consecutive)
            rows.append((table[keep], table[keep + 1]))
        if not rows:
            return cls(np.empty((0, COLUMNS)), np.empty((0, COLUMNS)))
        return cls(np.vstack([b for b, _ in rows]), np.vstack([a for _, a in rows]))

    def __len__(self) -> int:
        return self.before.shape[0]

    def measured(self) -> np.ndarray:
        """Shape (pairs, 3): the measured next state and the rise [l0] between the two feet."""
        return np.column_stack([self.after[:, 0], self.after[:, 1], self.after[:, 2] - self.before[:, 2]])


def pitch_at(times, frame_time: np.ndarray, frame_pitch: np.ndarray) -> np.ndarray:
    """The body's pitch [rad] at each touchdown time [s]: the median of the finite pitches of the
    frames in :data:`PITCH_WINDOW` around it; 0 where there are none (a tracker without pitch)."""
    result = np.zeros(len(times))
    for i, moment in enumerate(times):
        lo, hi = np.searchsorted(frame_time, [moment + PITCH_WINDOW[0], moment + PITCH_WINDOW[1]])
        window = frame_pitch[lo:hi]
        window = window[np.isfinite(window)]
        if window.size:
            result[i] = float(np.median(window))
    return result


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
def predict_pairs(before, after, alpha, d_hat, c_zeta, c_psi, mu, psi0_offsets, zeta0_offsets, out):
    """The detected touchdown ``k + 1`` the model predicts from each measured touchdown ``k``.

    Args:
        before, after: :class:`Pairs` columns; only ``after``'s controls, leg and pitch are read.
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
            xdot, ydot, psi0, zeta0, next_psi0, next_zeta0, alpha, d_hat, c_zeta, c_psi, mu, no_record
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


def sensitivities(pairs: Pairs, model_args: tuple, psi0_offsets: np.ndarray, zeta0_offsets: np.ndarray) -> np.ndarray:
    """Shape (pairs, 3, 6): how each predicted ``(xdot, ydot, rise)`` moves with the inputs of
    :data:`INPUTS` — the measured state ``(xdot, ydot)`` of touchdown ``k`` and the two legs'
    ``(psi0 [rad], zeta0 [l0])`` errors — by central differences; NaN where a jump fails."""
    result = np.empty((len(pairs), 3, len(INPUTS)))
    plus, minus = np.empty((len(pairs), 3)), np.empty((len(pairs), 3))
    for j, (table, column, step) in enumerate(INPUTS):
        for sign, out in ((1.0, plus), (-1.0, minus)):
            tables = {"before": pairs.before.copy(), "after": pairs.after.copy()}
            tables[table][:, column] += sign * step
            predict_pairs(tables["before"], tables["after"], *model_args, psi0_offsets, zeta0_offsets, out)
        result[:, :, j] = (plus - minus) / (2.0 * step)
    return result
