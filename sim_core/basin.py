"""Basins of attraction of a gait over a grid of section states (docs/model.md §4, paper Fig. 8).

Every cell of a grid over ``(xdot, ydot)`` is a start state; the map is iterated from it until
the orbit comes within ``tolerance`` of the gait's orbit (the cell is in the basin), a jump
fails, or ``max_jumps`` run out. The comparison respects the control schedule: after ``k``
jumps a state is compared only with the gait's orbit points of the same schedule phase
``k mod m``, since the legs in use must match too.

Arrays over the grid are indexed ``[row, column] = [ydot index, xdot index]`` (image order;
``ydot`` increases with the row). Areas are in nondimensional velocity units squared
(``g l0``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.basin_grid import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid
from sim_core.chunks import ChunkMap, Progress, chunk_slices, in_process
from sim_core.controls import ControlSchedule
from sim_core.failures import OK, Failure
from sim_core.fixed_points import FixedPoint
from sim_core.integrate import STATE_SIZE
from sim_core.params import ModelParams
from sim_core.poincare import check_jumps
from sim_core.stride import scheduled_jump
from sim_core.validation import ParameterError, check_range

DEFAULT_CHUNK_CELLS = 10_000  # ~0.3 s of work per chunk: fine-grained progress, cheap to ship
NOT_CONVERGED = -1  # jumps_to_converge of a cell that never reached the gait


@dataclass(frozen=True)
class Basin:
    """A gait's basin over a grid.

    Attributes:
        gait: the fixed point whose basin this is.
        grid: the start states.
        jumps_to_converge: shape (cells, cells) int; jumps until within ``tolerance`` of the
            gait's orbit, ``NOT_CONVERGED`` (-1) if never.
        failure: shape (cells, cells) int; the kernel status of the failing jump (0: none).
        max_jumps, tolerance: the convergence test.
        jumps_computed: the jumps the kernel simulated over all cells (for speed figures).
    """

    gait: FixedPoint
    grid: BasinGrid
    jumps_to_converge: np.ndarray
    failure: np.ndarray
    max_jumps: int
    tolerance: float
    jumps_computed: int

    @property
    def mask(self) -> np.ndarray:
        """True where the start state converges to the gait."""
        return self.jumps_to_converge != NOT_CONVERGED

    @property
    def fraction(self) -> float:
        return float(np.mean(self.mask))

    @property
    def area(self) -> float:
        """Basin area [g l0]: converged cells times the area per grid point."""
        return float(np.count_nonzero(self.mask)) * self.grid.cell_area

    def outcome_counts(self) -> dict[str, int]:
        """Cells per outcome: ``converged``, ``not_converged`` (no failure either) and each failure code."""
        counts = {
            "converged": int(np.count_nonzero(self.mask)),
            "not_converged": int(np.count_nonzero(~self.mask & (self.failure == OK))),
        }
        for failure in Failure:
            counts[failure.code] = int(np.count_nonzero(self.failure == failure.value))
        return counts

    def to_dict(self, *, include_grids: bool = True) -> dict:
        """The ``parkour basin --json`` contract."""
        result = {
            "gait": {"state": self.gait.state.tolist(), "period": self.gait.period},
            "xdot_range": list(self.grid.xdot_range),
            "ydot_range": list(self.grid.ydot_range),
            "grid": self.grid.cells,
            "jumps": self.max_jumps,
            "tolerance": self.tolerance,
            "area": self.area,
            "fraction": self.fraction,
            "counts": self.outcome_counts(),
            "jumps_computed": self.jumps_computed,
        }
        if include_grids:
            result["failure_codes"] = {"0": None, **{str(f.value): f.code for f in Failure}}
            result["jumps_to_converge"] = self.jumps_to_converge.tolist()
            result["failure"] = self.failure.tolist()
        return result


def check_convergence_test(max_jumps: int, tolerance: float) -> tuple[int, float]:
    """Validate the basin's convergence test; returns ``(max_jumps, tolerance)``."""
    return check_jumps(max_jumps), check_range("tolerance", tolerance, 0.0, 10.0)


def compute_basin(
    model: ModelParams,
    schedule: ControlSchedule,
    gait: FixedPoint,
    grid: BasinGrid,
    *,
    max_jumps: int = DEFAULT_JUMPS,
    tolerance: float = DEFAULT_TOLERANCE,
    chunk_map: ChunkMap = in_process,
    chunk_cells: int = DEFAULT_CHUNK_CELLS,
    progress: Progress | None = None,
) -> Basin:
    """The basin of ``gait`` (a fixed point of ``schedule``) over ``grid``.

    The cells are split into chunks of ``chunk_cells`` run by ``chunk_map``
    (:mod:`sim_core.chunks`; in-process on all cores by default).
    """
    max_jumps, tolerance = check_convergence_test(max_jumps, tolerance)
    if gait.period % len(schedule) != 0:
        raise ParameterError("gait", f"period {gait.period} is not a multiple of the schedule length {len(schedule)}")
    starts = grid.states()
    arguments = [
        (model, schedule, gait.orbit, starts[part], max_jumps, tolerance)
        for part in chunk_slices(starts.shape[0], chunk_cells)
    ]
    parts = chunk_map(converge_states, arguments, progress)
    jumps_to_converge, failure, jumps_done = (np.concatenate(column) for column in zip(*parts, strict=True))
    shape = (grid.cells, grid.cells)
    return Basin(
        gait=gait,
        grid=grid,
        jumps_to_converge=jumps_to_converge.reshape(shape),
        failure=failure.reshape(shape),
        max_jumps=max_jumps,
        tolerance=tolerance,
        jumps_computed=int(jumps_done.sum()),
    )


def converge_states(
    model: ModelParams,
    schedule: ControlSchedule,
    orbit: np.ndarray,
    starts: np.ndarray,
    max_jumps: int,
    tolerance: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The basin test for each row of ``starts`` (N, 2) on all cores: one chunk of a basin.

    Returns int arrays ``(jumps_to_converge, failure status, jumps simulated)``, shape (N,).
    """
    starts = np.ascontiguousarray(starts, dtype=np.float64)
    count = starts.shape[0]
    jumps_to_converge = np.empty(count, dtype=np.int64)
    failure = np.empty(count, dtype=np.int64)
    jumps_done = np.empty(count, dtype=np.int64)
    converge_batch(
        starts,
        schedule.as_array(),
        np.ascontiguousarray(orbit, dtype=np.float64),
        tolerance,
        max_jumps,
        *model.kernel_args(),
        jumps_to_converge,
        failure,
        jumps_done,
    )
    return jumps_to_converge, failure, jumps_done


@kernel
def _near_orbit(xdot, ydot, phase, period, orbit, tolerance):
    """Whether ``(xdot, ydot)`` at schedule phase ``phase`` lies within ``tolerance`` of the orbit."""
    for j in range(phase, orbit.shape[0], period):
        if math.hypot(xdot - orbit[j, 0], ydot - orbit[j, 1]) < tolerance:
            return True
    return False


@kernel
def converge(xdot, ydot, schedule, orbit, tolerance, max_jumps, alpha, d_hat, c_zeta, c_psi, mu):
    """Iterate from one start until it reaches ``orbit``, fails, or ``max_jumps`` run out.

    Returns ``(jumps_to_converge or NOT_CONVERGED, status, jumps_simulated)``.
    """
    period = schedule.shape[0]
    no_record = np.empty((0, STATE_SIZE))
    if _near_orbit(xdot, ydot, 0, period, orbit, tolerance):
        return 0, OK, 0
    for k in range(max_jumps):
        status, xdot, ydot, _ = scheduled_jump(xdot, ydot, schedule, k, alpha, d_hat, c_zeta, c_psi, mu, no_record)
        if status != OK:
            return NOT_CONVERGED, status, k + 1
        if _near_orbit(xdot, ydot, (k + 1) % period, period, orbit, tolerance):
            return k + 1, OK, k + 1
    return NOT_CONVERGED, OK, max_jumps


@parallel_kernel
def converge_batch(
    starts, schedule, orbit, tolerance, max_jumps, alpha, d_hat, c_zeta, c_psi, mu, jumps_to_converge, failure, done
):
    """:func:`converge` for each row of ``starts`` (N, 2) on all cores; outputs are (N,) int arrays."""
    for i in prange(starts.shape[0]):
        jumps_to_converge[i], failure[i], done[i] = converge(
            starts[i, 0], starts[i, 1], schedule, orbit, tolerance, max_jumps, alpha, d_hat, c_zeta, c_psi, mu
        )
