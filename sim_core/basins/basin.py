"""Basins of attraction of a gait over a grid of section states (docs/model.md §4, paper Fig. 8).

Every cell of a grid over ``(xdot, ydot)`` is a start state; the map is iterated from it until
the orbit comes within ``tolerance`` of the gait's orbit (the cell is in the basin), a jump
fails, or ``max_jumps`` run out (the cell is undecided). With a ``jump_limit`` above
``max_jumps``, undecided cells are continued in rounds, the cap doubled each round, until they
decide or the limit is reached (:mod:`sim_core.basins.cells`). The comparison respects the control
schedule: after ``k`` jumps a state is compared only with the gait's orbit points of the same
schedule phase ``k mod m``, since the legs in use must match too.

Arrays over the grid are indexed ``[row, column] = [ydot index, xdot index]`` (image order;
``ydot`` increases with the row). Areas are in nondimensional velocity units squared
(``g l0``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_core.basins.cells import NOT_CONVERGED, caps, check_jump_limit, converge_states, is_falling
from sim_core.basins.grid import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid
from sim_core.chunks import ChunkMap, Progress, chunk_slices, in_process
from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK, Failure
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_jumps
from sim_core.model.validation import ParameterError, check_range
from sim_core.section.fixed_points import FixedPoint

DEFAULT_CHUNK_CELLS = 10_000  # ~0.3 s of work per chunk: fine-grained progress, cheap to ship


@dataclass(frozen=True)
class Basin:
    """A gait's basin over a grid.

    Attributes:
        gait: the fixed point whose basin this is.
        grid: the start states.
        jumps_to_converge: shape (cells, cells) int; jumps until within ``tolerance`` of the
            gait's orbit, ``NOT_CONVERGED`` (-1) if never.
        failure: shape (cells, cells) int; the kernel status of the failing jump (0: none).
        max_jumps, tolerance: the convergence test; ``max_jumps`` is the first cap.
        jump_limit: the most jumps any cell was run (``max_jumps``: no continuation).
        jumps_run: shape (cells, cells) int; the jumps simulated from each start.
        stopped_at: shape (cells, cells, 2); the section state each run stopped at [sqrt(g l0)]
            (a failed run: the state before the failing jump).
    """

    gait: FixedPoint
    grid: BasinGrid
    jumps_to_converge: np.ndarray
    failure: np.ndarray
    max_jumps: int
    tolerance: float
    jump_limit: int
    jumps_run: np.ndarray
    stopped_at: np.ndarray

    @property
    def mask(self) -> np.ndarray:
        """True where the start state converges to the gait."""
        return self.jumps_to_converge != NOT_CONVERGED

    @property
    def undecided(self) -> np.ndarray:
        """True where the run neither converged nor failed within the jump limit."""
        return ~self.mask & (self.failure == OK)

    @property
    def falling(self) -> np.ndarray:
        """True where an undecided run was falling (past ``basin_cells.FALLING_SPEED``): no limit decides it."""
        return self.undecided & is_falling(self.stopped_at)

    @property
    def fraction(self) -> float:
        return float(np.mean(self.mask))

    @property
    def jumps_computed(self) -> int:
        """The jumps simulated over all cells (for speed figures)."""
        return int(self.jumps_run.sum())

    def rounds(self) -> list[dict[str, int]]:
        """Cells converged and still undecided at each cap of the rounds, from ``max_jumps`` to the
        limit: what a single run with that cap would have reported."""
        converged = self.jumps_to_converge[self.mask]

        def decided_by(cap: int) -> np.ndarray:  # converged or failed within cap jumps (a falling run never decides)
            return (self.mask | (self.failure != OK)) & (self.jumps_run <= cap)

        return [
            {
                "cap": cap,
                "converged": int(np.count_nonzero(converged <= cap)),
                "undecided": int(np.count_nonzero(~decided_by(cap))),
            }
            for cap in caps(self.max_jumps, self.jump_limit)
        ]

    @property
    def area(self) -> float:
        """Basin area [g l0]: converged cells times the area per grid point."""
        return float(np.count_nonzero(self.mask)) * self.grid.cell_area

    def outcome_counts(self) -> dict[str, int]:
        """Cells per outcome: ``converged``, ``not_converged`` (no failure either) and each failure code."""
        counts = {
            "converged": int(np.count_nonzero(self.mask)),
            "not_converged": int(np.count_nonzero(self.undecided)),
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
            "jump_limit": self.jump_limit,
            "undecided": int(np.count_nonzero(self.undecided)),
            "falling": int(np.count_nonzero(self.falling)),
            "rounds": self.rounds(),
        }
        if include_grids:
            result["failure_codes"] = {"0": None, **{str(f.value): f.code for f in Failure}}
            result["jumps_to_converge"] = self.jumps_to_converge.tolist()
            result["failure"] = self.failure.tolist()
        return result


def check_convergence_test(max_jumps: int, tolerance: float, jump_limit: int | None = None) -> tuple[int, float, int]:
    """Validate the basin's convergence test; returns ``(max_jumps, tolerance, jump_limit)``, the
    limit ``max_jumps`` when None."""
    max_jumps = check_jumps(max_jumps)
    return max_jumps, check_range("tolerance", tolerance, 0.0, 10.0), check_jump_limit(jump_limit, max_jumps)


def compute_basin(
    model: ModelParams,
    schedule: ControlSchedule,
    gait: FixedPoint,
    grid: BasinGrid,
    *,
    max_jumps: int = DEFAULT_JUMPS,
    tolerance: float = DEFAULT_TOLERANCE,
    jump_limit: int | None = None,
    chunk_map: ChunkMap = in_process,
    chunk_cells: int = DEFAULT_CHUNK_CELLS,
    progress: Progress | None = None,
) -> Basin:
    """The basin of ``gait`` (a fixed point of ``schedule``) over ``grid``.

    Every cell runs up to ``max_jumps`` jumps; with ``jump_limit`` (at least ``max_jumps``; None:
    ``max_jumps``) the undecided ones are continued, the cap doubled each round, up to
    ``jump_limit`` jumps from their start. The cells are split into chunks of ``chunk_cells`` run
    by ``chunk_map`` (:mod:`sim_core.chunks`; in-process on all cores by default).
    """
    max_jumps, tolerance, jump_limit = check_convergence_test(max_jumps, tolerance, jump_limit)
    if gait.period % len(schedule) != 0:
        raise ParameterError("gait", f"period {gait.period} is not a multiple of the schedule length {len(schedule)}")
    starts = grid.states()
    arguments = [
        (model, schedule, gait.orbit, starts[part], max_jumps, tolerance, jump_limit)
        for part in chunk_slices(starts.shape[0], chunk_cells)
    ]
    parts = chunk_map(converge_states, arguments, progress)
    jumps_to_converge, failure, jumps_run, stopped_at = (np.concatenate(column) for column in zip(*parts, strict=True))
    shape = (grid.cells, grid.cells)
    return Basin(
        gait=gait,
        grid=grid,
        jumps_to_converge=jumps_to_converge.reshape(shape),
        failure=failure.reshape(shape),
        max_jumps=max_jumps,
        tolerance=tolerance,
        jump_limit=jump_limit,
        jumps_run=jumps_run.reshape(shape),
        stopped_at=stopped_at.reshape((*shape, 2)),
    )
