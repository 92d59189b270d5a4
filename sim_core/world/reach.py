"""Reach in a world: over a grid of controls, how high a fixed schedule climbs and how it ends
(docs/model.md §8).

Each cell holds one symmetric schedule ``(psi0, zeta0)``; from touchdown 0 (the foot on the left
side at ``foot_y``, the body arriving with ``state``) it climbs up to ``jumps`` jumps, with no
noise or pitch, until its foot reaches the world's top (:attr:`World.top`, ending ``top``: the
chute climbed) or the body touches down below the floor (``floor``, docs/model.md §7.2, as a
closed loop's touchdowns are tested). A cell reports the highest foot reached and the last [l0],
the jumps completed and its ending: ``top``, ``capped`` (every jump done below the top) or the
failure's code — a failure map by code. The grid runs in chunks of ``zeta0`` rows through a
chunk map (:mod:`sim_core.chunks`), so a cluster can take them; results do not depend on how it
is split.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sim_core.chunks import ChunkMap, Progress, chunk_slices, in_process
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import FLOOR, FLOOR_HEIGHT, OK, Failure
from sim_core.model.params import ModelParams
from sim_core.model.poincare import check_jumps, check_section_state
from sim_core.model.validation import ParameterError, check_range
from sim_core.world.climb import first_touchdown
from sim_core.world.geometry import pack
from sim_core.world.stride import TOUCHDOWN_SIZE, Y, world_orbit_batch
from sim_core.world.world import World

TOP = "top"  # the climb's foot reached the world's top: the chute climbed
CAPPED = "capped"  # every jump of the cell done, below the top
MAX_CELLS = 250_000  # a grid's cells
MAX_CELL_JUMPS = 25_000_000  # cells x jumps: about a minute on two cores
DEFAULT_CHUNK_ROWS = 8


@dataclass(frozen=True)
class ReachMap:
    """A reach study's grid: rows by ``zeta0``, columns by ``psi0``.

    Attributes:
        psi0_deg: shape (P,), the columns' leg angles [deg]; zeta0: shape (Z,), the rows'.
        highest: shape (Z, P), the highest foot of the climb [l0] (touchdown 0's included).
        last: shape (Z, P), the foot of the last touchdown reached [l0].
        completed: shape (Z, P), jumps completed; status: shape (Z, P), 0 for capped else a
            :class:`~sim_core.model.failures.Failure` value.
    """

    world: str
    state: tuple[float, float]
    foot_y: float
    jumps: int
    top: float
    psi0_deg: np.ndarray
    zeta0: np.ndarray
    highest: np.ndarray
    last: np.ndarray
    completed: np.ndarray
    status: np.ndarray
    topped: np.ndarray

    def endings(self) -> np.ndarray:
        """Each cell's ending as a code: ``capped`` or the failure's code, shape (Z, P)."""
        codes = {OK: CAPPED} | {failure.value: failure.code for failure in Failure}
        endings = np.vectorize(codes.__getitem__, otypes=[object])(self.status)
        endings[self.topped] = TOP
        return endings

    def outcomes(self) -> dict[str, int]:
        """How many cells ended each way: ``capped`` and every failure code, in that order."""
        counts = {TOP: int(np.count_nonzero(self.topped))}
        counts[CAPPED] = int(np.count_nonzero((self.status == OK) & ~self.topped))
        return counts | {failure.code: int(np.count_nonzero(self.status == failure.value)) for failure in Failure}

    def to_dict(self) -> dict:
        """The ``parkour reach --json`` contract: grids as lists of rows (one per zeta0)."""
        return {
            "world": self.world,
            "state": list(self.state),
            "foot_y": self.foot_y,
            "jumps": self.jumps,
            "top": self.top,
            "psi0_deg": self.psi0_deg.tolist(),
            "zeta0": self.zeta0.tolist(),
            "highest": self.highest.tolist(),
            "last": self.last.tolist(),
            "completed": self.completed.tolist(),
            "ending": self.endings().tolist(),
            "outcomes": self.outcomes(),
        }


def reach_rows(
    model: ModelParams, world: World, psi0s: np.ndarray, zeta0s: np.ndarray, state, jumps: int, foot_y: float
) -> tuple[np.ndarray, ...]:
    """One chunk: the cells of ``zeta0s`` x ``psi0s`` [rad], ``(highest, last, completed, status,
    topped)`` each of shape (len(zeta0s), len(psi0s))."""
    cells = [(zeta0, psi0) for zeta0 in zeta0s for psi0 in psi0s]
    starts = np.empty((len(cells), jumps + 1, TOUCHDOWN_SIZE))
    on_side = np.zeros((len(cells), jumps + 1), dtype=np.int64)
    on_segment = np.zeros((len(cells), jumps + 1), dtype=np.int64)
    schedules = np.empty((len(cells), 1, 2))
    for i, (zeta0, psi0) in enumerate(cells):
        schedule = ControlSchedule.of(LegControl(float(psi0), float(zeta0)))
        starts[i, 0], on_segment[i, 0] = first_touchdown(model, world, schedule, state, foot_y)
        schedules[i] = schedule.as_array()
    status = np.empty(len(cells), dtype=np.int64)
    completed = np.empty(len(cells), dtype=np.int64)
    world_orbit_batch(schedules, 0, model.record(), pack(world, model.mu), starts, on_side, on_segment,
                      status, completed)  # fmt: skip
    # a foot is the body at touchdown less the leg that touched down (every row: this cell's leg)
    feet = starts[:, :, Y] - (schedules[:, 0, 1] * np.sin(schedules[:, 0, 0]))[:, np.newaxis]
    ended = _first(starts[:, 1:, Y] < FLOOR_HEIGHT) + 1  # touchdown k below the floor: jump k failed
    topped = _first(feet[:, 1:] >= world.top) + 1  # touchdown k's foot at the top: done
    floor = ended <= np.minimum(completed, topped - 1)
    status[floor], completed[floor] = FLOOR, ended[floor] - 1
    reached = ~floor & (topped <= completed)
    status[reached], completed[reached] = OK, topped[reached]
    kept = np.arange(jumps + 1) <= completed[:, np.newaxis]
    kept[floor, completed[floor] + 1] = False
    highest = np.max(np.where(kept, feet, -np.inf), axis=1)
    last = feet[np.arange(len(cells)), completed]
    shape = (len(zeta0s), len(psi0s))
    return tuple(part.reshape(shape) for part in (highest, last, completed, status, reached))


def _first(hits: np.ndarray) -> np.ndarray:
    """Each row's first index where ``hits`` holds, or the row's length where none does."""
    return np.where(hits.any(axis=1), hits.argmax(axis=1), hits.shape[1])


def reach_map(
    model: ModelParams,
    world: World,
    psi0_deg: Sequence[float],
    zeta0s: Sequence[float],
    state,
    jumps: int,
    *,
    foot_y: float = 0.0,
    chunk_map: ChunkMap = in_process,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    progress: Progress | None = None,
) -> ReachMap:
    """The reach of every symmetric schedule of the grid ``psi0_deg`` x ``zeta0s`` in ``world``."""
    arguments = reach_chunks(model, world, psi0_deg, zeta0s, state, jumps, foot_y, chunk_rows)
    return reach_of(world, state, foot_y, jumps, psi0_deg, zeta0s, chunk_map(reach_rows, arguments, progress))


def _checked(psi0_deg, zeta0s, state, jumps, foot_y) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, float]:
    """The grid's inputs checked (a ParameterError naming the first wrong one): ``(psi0_deg, zeta0s,
    velocity, jumps, foot_y)`` as the map holds them."""
    velocity = check_section_state(state)
    jumps = check_jumps(jumps)
    foot_y = check_range("foot_y", foot_y)
    psi0_deg = np.array([check_range("psi0_deg", value, 0.0, 90.0) for value in psi0_deg], dtype=float)
    zeta0s = np.array([check_range("zeta0", value, 0.0, 1.0) for value in zeta0s], dtype=float)
    cells = psi0_deg.size * zeta0s.size
    if not 1 <= cells <= MAX_CELLS:
        raise ParameterError("grid", f"must have 1 to {MAX_CELLS:,} cells (psi0 x zeta0), got {cells:,}")
    if cells * jumps > MAX_CELL_JUMPS:
        raise ParameterError(
            "jumps", f"cells x jumps must be at most {MAX_CELL_JUMPS:,}, got {cells:,} x {jumps:,}: ask for fewer"
        )
    return psi0_deg, zeta0s, velocity, jumps, foot_y


def reach_chunks(
    model: ModelParams,
    world: World,
    psi0_deg: Sequence[float],
    zeta0s: Sequence[float],
    state,
    jumps: int,
    foot_y: float = 0.0,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
) -> list[tuple]:
    """The grid's chunks, checked: :func:`reach_rows`'s arguments for each block of ``chunk_rows``
    rows of ``zeta0s``, in order (a job runs them one by one: ``backend/jobs/reach.py``)."""
    psi0_deg, zeta0s, velocity, jumps, foot_y = _checked(psi0_deg, zeta0s, state, jumps, foot_y)
    psi0s = np.radians(psi0_deg)
    return [(model, world, psi0s, zeta0s[part], tuple(velocity), jumps, foot_y)
            for part in chunk_slices(zeta0s.size, chunk_rows)]  # fmt: skip


def reach_of(
    world: World,
    state,
    foot_y: float,
    jumps: int,
    psi0_deg: Sequence[float],
    zeta0s: Sequence[float],
    rows: Sequence[Sequence[np.ndarray]],
) -> ReachMap:
    """The map of the grid from its chunks' :func:`reach_rows` results (``rows``, in the order of
    :func:`reach_chunks`; arrays, or the same as nested lists)."""
    psi0_deg, zeta0s, velocity, jumps, foot_y = _checked(psi0_deg, zeta0s, state, jumps, foot_y)
    types = (float, float, np.int64, np.int64, bool)
    highest, last, completed, status, topped = (
        np.concatenate([np.asarray(result[k], dtype=kind).reshape(-1, psi0_deg.size) for result in rows])
        for k, kind in enumerate(types)
    )
    if highest.shape != (zeta0s.size, psi0_deg.size):
        raise ValueError(f"the chunks hold {highest.shape[0]} rows of zeta0, the grid has {zeta0s.size}")
    return ReachMap(world.name or "unnamed", (float(velocity[0]), float(velocity[1])), foot_y, jumps, world.top,
                    psi0_deg, zeta0s, highest, last, completed, status, topped)  # fmt: skip


def grid_values(low: float, high: float, steps: int) -> np.ndarray:
    """``steps`` evenly spaced values from ``low`` to ``high`` (one: ``low``), an axis of the grid."""
    if isinstance(steps, bool) or int(steps) != steps or not 1 <= steps <= 1000:
        raise ParameterError("steps", f"must be an integer in [1, 1000], got {steps!r}")
    return np.linspace(low, high, int(steps)) if steps > 1 else np.array([low], dtype=float)
