"""The gait atlas: where stable gaits live over a grid of controls, and what they do.

Each cell of the grid is a control schedule (symmetric ``(psi0, zeta0)``, or L/R pairs). From
several start states per cell the map is iterated past its transient — all cells and starts in
one batch on all cores — and the cycle each orbit approaches is read off (its period, up to
``MAX_PERIOD`` jumps, from a tail that repeats to ``SETTLED``), then refined by
Levenberg–Marquardt to an exact fixed point with eigenvalues and climb; only stable ones are
kept. Gaits with |λ| near 1 attract slowly: a longer transient finds more of them. A cell can
hold several gaits.

Arrays over the grid are indexed ``[row, column]``; the caller names the two axes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sim_core.chunks import ChunkMap, Progress, chunk_slices, in_process
from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK
from sim_core.model.params import ModelParams
from sim_core.model.poincare import iterate_map_batch
from sim_core.model.validation import ParameterError
from sim_core.section.atlas_plan import DEFAULT_STARTS, MAX_CELLS, MAX_PERIOD, TRANSIENT_JUMPS
from sim_core.section.fixed_points import FixedPoint, FixedPointNotFound, find_fixed_point

SETTLED = 1e-2  # [sqrt(g l0)]: a tail repeating to this is near a cycle; Levenberg–Marquardt finishes the job
CHUNK_ORBITS = 4096


@dataclass(frozen=True)
class GaitAtlas:
    """Stable gaits over a grid of control schedules.

    Attributes:
        row_label, column_label: what the axes are (e.g. ``"psi0_deg"``, ``"zeta0"``).
        rows, columns: the axis values.
        gaits: per cell (row-major), the distinct stable gaits found, most stable first.
    """

    row_label: str
    column_label: str
    rows: np.ndarray
    columns: np.ndarray
    gaits: tuple[tuple[FixedPoint, ...], ...]

    def _grid(self, value, empty=math.nan) -> np.ndarray:
        cells = [value(gaits[0]) if gaits else empty for gaits in self.gaits]
        return np.array(cells, dtype=float).reshape(self.rows.size, self.columns.size)

    @property
    def count(self) -> np.ndarray:
        """Number of distinct stable gaits per cell."""
        return np.array([len(g) for g in self.gaits]).reshape(self.rows.size, self.columns.size)

    @property
    def period(self) -> np.ndarray:
        """Period [jumps] of each cell's most stable gait; 0 where none."""
        return self._grid(lambda gait: gait.period, 0).astype(int)

    @property
    def climb_per_jump(self) -> np.ndarray:
        """Climb per jump [l0] of each cell's most stable gait; NaN where none."""
        return self._grid(lambda gait: gait.climb_per_period / gait.period)

    @property
    def max_abs_eigenvalue(self) -> np.ndarray:
        return self._grid(lambda gait: gait.max_abs_eigenvalue)

    def to_dict(self) -> dict:
        """The ``parkour atlas --json`` contract."""
        return {
            "row_label": self.row_label,
            "column_label": self.column_label,
            "rows": self.rows.tolist(),
            "columns": self.columns.tolist(),
            "period": self.period.tolist(),
            "climb_per_jump": self.climb_per_jump.tolist(),
            "max_abs_eigenvalue": self.max_abs_eigenvalue.tolist(),
            "count": self.count.tolist(),
            "cells": [
                [
                    {
                        "state": gait.state.tolist(),
                        "period": gait.period,
                        "max_abs_eigenvalue": gait.max_abs_eigenvalue,
                        "climb_per_jump": gait.climb_per_period / gait.period,
                    }
                    for gait in gaits
                ]
                for gaits in self.gaits
            ],
        }


def gait_atlas(
    model: ModelParams,
    schedules: Sequence[ControlSchedule],
    rows: Sequence[float],
    columns: Sequence[float],
    *,
    row_label: str,
    column_label: str,
    starts: Sequence[tuple[float, float]] = DEFAULT_STARTS,
    transient_jumps: int = TRANSIENT_JUMPS,
    chunk_map: ChunkMap = in_process,
    progress: Progress | None = None,
) -> GaitAtlas:
    """The atlas over ``schedules`` (row-major, ``len(rows) * len(columns)`` of equal length)."""
    rows, columns = np.asarray(rows, dtype=float), np.asarray(columns, dtype=float)
    cells = rows.size * columns.size
    if not 1 <= cells <= MAX_CELLS:
        raise ParameterError("grid", f"must have 1 to {MAX_CELLS:,} cells, got {rows.size} x {columns.size}")
    if len(schedules) != cells:
        raise ParameterError("schedules", f"need one per cell ({cells}), got {len(schedules)}")
    length = len(schedules[0])
    if any(len(schedule) != length for schedule in schedules):
        raise ParameterError("schedules", "all cells need schedules of the same length")
    starts_array = np.asarray(starts, dtype=float)
    per_cell = starts_array.shape[0]
    kept = 2 * MAX_PERIOD * length
    initial = np.tile(starts_array, (cells, 1))
    table = np.repeat(np.stack([s.as_array() for s in schedules]), per_cell, axis=0)
    arguments = [
        (model, table[part], initial[part], transient_jumps, kept)
        for part in chunk_slices(initial.shape[0], CHUNK_ORBITS)
    ]
    tails = np.concatenate(chunk_map(attractor_tails, arguments, progress))
    found: list[tuple[FixedPoint, ...]] = []
    for cell in range(cells):
        candidates = {}
        for tail in tails[cell * per_cell : (cell + 1) * per_cell]:
            period = _period(tail, length)
            if period:
                key = tuple(np.round(np.sort(tail[:period], axis=0), 2).ravel())
                candidates.setdefault(key, (tail[0], period))
        gaits = []
        for state, period in candidates.values():
            try:
                gaits.append(find_fixed_point(model, schedules[cell], period, state))
            except FixedPointNotFound:
                continue
        unique = []
        for gait in sorted(gaits, key=lambda g: g.max_abs_eigenvalue):
            if gait.stable and not any(_same(gait, known, length) for known in unique):
                unique.append(gait)
        found.append(tuple(unique))
    return GaitAtlas(row_label, column_label, rows, columns, tuple(found))


def attractor_tails(
    model: ModelParams, schedules: np.ndarray, starts: np.ndarray, transient_jumps: int, kept: int
) -> np.ndarray:
    """The last ``kept`` section states after ``transient_jumps`` (NaN rows where an orbit failed).

    One chunk of an atlas: shape (N, kept, 2), the first kept state at schedule phase 0.
    """
    total = transient_jumps + kept
    total -= total % schedules.shape[1]  # end at phase 0
    batch = iterate_map_batch(model, schedules, starts, total)
    tails = batch.states[:, total - kept : total, :].copy()
    tails[batch.status != OK] = np.nan
    return tails


def _period(tail: np.ndarray, length: int) -> int:
    """Smallest period (a multiple of the schedule length, <= MAX_PERIOD) of a settled tail, else 0."""
    if not np.isfinite(tail).all():
        return 0
    for period in range(length, MAX_PERIOD + 1, length):
        if np.max(np.abs(tail[period:] - tail[:-period])) <= SETTLED:
            return period
    return 0


def _same(a: FixedPoint, b: FixedPoint, length: int) -> bool:
    """Whether ``a`` lies on ``b``'s orbit at the same schedule phase."""
    if a.period != b.period:
        return False
    return bool(np.min(np.linalg.norm(b.orbit[::length] - a.state, axis=1)) < 1e-6)
