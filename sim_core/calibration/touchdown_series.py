"""Tracked touchdowns as calibration reads them: one run's series, the pairs of runs, the pitch at
each (docs/calibration.md). Plain numpy, no kernels: the service builds these without loading
numba; :mod:`sim_core.calibration.touchdown_model` predicts them.

Units: states in ``sqrt(g l0)``, heights in ``l0``, angles in radians; walls as in
:mod:`sim_core.model.walls`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from sim_core.model.validation import ParameterError

# Tracker frames whose pitch is a touchdown's: the 50 ms before the detected crossing [s], the end of
# the flight, whose pitch the leg reached with (the body's pitch steps at lift-off).
PITCH_WINDOW = (-0.05, 0.0)

COLUMNS = 9  # of Pairs.before and .after
# Pairs left out at the end of a run that fell: the jump into the touchdown its failing jump began at
# (a jump on the edge of failing, often a long slow flight the map cannot linearise) and, on a real
# robot, anything the detector found while the robot fell (docs/calibration.md, "Falls").
FALL_PAIRS = 1
PSI0_ERROR, ZETA0_ERROR = 7, 8
# The channels a pair compares: the next touchdown's section state and the rise to it.
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
        fell: whether the run ended in a fall (the robot's FELL fault): the jump from its last
            touchdown failed.
    """

    state: np.ndarray
    foot_height: np.ndarray
    commanded: np.ndarray
    right_leg: np.ndarray
    pitch: np.ndarray
    consecutive: np.ndarray
    fell: bool = False

    def __post_init__(self) -> None:
        n = self.state.shape[0]
        shapes = {"state": (n, 2), "foot_height": (n,), "commanded": (n, 2), "right_leg": (n,), "pitch": (n,),
                  "consecutive": (max(n - 1, 0),)}  # fmt: skip
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise ParameterError(name, f"must have shape {shape}, got {getattr(self, name).shape}")

    @classmethod
    def of(cls, *, state, foot_height, commanded, right_leg, pitch=None, fell: bool = False) -> TouchdownSeries:
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
            fell=bool(fell),
        )

    @property
    def pairs(self) -> int:
        return int(np.count_nonzero(self.consecutive))

    @property
    def steady(self) -> np.ndarray:
        """Shape (n - 1,): the consecutive pairs less, in a run that fell, its last :data:`FALL_PAIRS`."""
        keep = self.consecutive.copy()
        if self.fell:
            keep[max(keep.size - FALL_PAIRS, 0) :] = False
        return keep


@dataclass(frozen=True)
class Pairs:
    """Consecutive touchdown pairs ``k -> k + 1`` of any number of runs, as the kernel takes them.

    ``before`` and ``after`` hold, per pair, columns ``xdot, ydot, foot_height, psi0_commanded,
    zeta0_commanded, right_leg (0/1), pitch, psi0_error, zeta0_error`` of touchdown ``k`` and
    ``k + 1``; the errors (0 as measured) are what the leg realised beyond the commanded, offset and
    pitch — the per-jump control noise — and let :func:`sensitivities` ask what it would change.
    ``origin`` (pairs, 2) says where each pair is from: the series' position in the list and
    ``k + 1``, the index of the touchdown it predicts.
    """

    before: np.ndarray
    after: np.ndarray
    origin: np.ndarray

    @classmethod
    def of(cls, series: list[TouchdownSeries], *, steady: bool = False) -> Pairs:
        """The consecutive pairs of ``series``; ``steady``: less those of a fall (:attr:`TouchdownSeries.steady`)."""
        rows = []
        for position, run in enumerate(series):
            errors = np.zeros((run.right_leg.size, 2))
            table = np.column_stack([run.state, run.foot_height, run.commanded, run.right_leg, run.pitch, errors])
            keep = np.flatnonzero(run.steady if steady else run.consecutive)
            rows.append((table[keep], table[keep + 1], np.column_stack([np.full(keep.size, position), keep + 1])))
        if not rows:
            return cls(np.empty((0, COLUMNS)), np.empty((0, COLUMNS)), np.empty((0, 2), dtype=int))
        return cls(*(np.vstack([row[part] for row in rows]) for part in range(3)))

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


def pitch_drift_deg(series: list[TouchdownSeries]) -> float:
    """The standard deviation [deg] of the pitch's change from one touchdown to the next (its
    random walk's step, docs/model.md §5.1), over consecutive pairs; 0 without tracked pitch."""
    steps = [np.diff(run.pitch)[run.consecutive] for run in series if run.pitch.size > 1]
    steps = np.concatenate(steps) if steps else np.empty(0)
    if steps.size < 2 or not np.any(steps):
        return 0.0
    return float(np.degrees(np.std(steps, ddof=1)))


def finite_rms(values: np.ndarray, axis=None):
    """Root mean square over the finite values (a failed prediction has none to give); NaN where
    there are none."""
    squared = np.where(np.isfinite(values), values, np.nan) ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a column without a finite value is NaN
        result = np.sqrt(np.nanmean(squared, axis=axis))
    return result if axis is not None else float(result)
