"""Energy sweeps: a gait followed over leg retraction zeta0 (paper Fig. 8, docs/model.md §5).

For each zeta0 of a sweep the fixed point is solved by continuation — seeded from the
neighbour's solution — and characterised: max |eigenvalue|, stability, climb per jump, and
optionally its basin area on one fixed window (so areas compare across the sweep). Where the
climb changes sign between neighbours, the zeta0 of jumping in place is located by Brent's
method on ``climb(zeta0)``.

Either both legs sweep together (symmetric controls), or one leg is held fixed and the
other sweeps (schedule ``[fixed leg, swept leg]``, period 2).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sim_core.basins.cells import NOT_CONVERGED, check_jump_limit, converge_states
from sim_core.basins.grid import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid
from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import OK
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError, check_range
from sim_core.section.fixed_points import FixedPoint, FixedPointNotFound, find_fixed_point
from sim_core.section.gait_search import gait_of

MAX_STEPS = 10_000
IN_PLACE_XTOL = 1e-9  # [l0 of zeta0]


@dataclass(frozen=True)
class SweepPoint:
    """One zeta0 of a sweep; ``gait`` is None where continuation found no fixed point."""

    zeta0: float
    energy: float  # stored spring energy alpha (1 - zeta0)^2 / 2 [m g l0]
    gait: FixedPoint | None
    basin_area: float | None  # [g l0]; None when not computed
    basin_undecided: int | None = None  # cells neither converged nor failed within the jump limit

    @property
    def climb_per_jump(self) -> float:
        return math.nan if self.gait is None else self.gait.climb_per_period / self.gait.period

    def to_dict(self) -> dict:
        gait = self.gait
        return {
            "zeta0": self.zeta0,
            "energy": self.energy,
            "found": gait is not None,
            "state": None if gait is None else gait.state.tolist(),
            "period": None if gait is None else gait.period,
            "max_abs_eigenvalue": None if gait is None else gait.max_abs_eigenvalue,
            "stable": None if gait is None else gait.stable,
            "climb_per_jump": None if gait is None else self.climb_per_jump,
            "basin_area": self.basin_area,
            "basin_undecided": self.basin_undecided,
        }


@dataclass(frozen=True)
class EnergySweep:
    """A gait over a range of zeta0.

    Attributes:
        psi0: the swept leg's angle [rad].
        fixed_leg: the leg held fixed, or None for symmetric controls.
        points: one per zeta0, in sweep order.
        in_place_zeta0: the zeta0 values where the climb crosses zero (jumping in place).
        basin_grid: the window and resolution of the basin areas, or None.
        basin_jumps, basin_jump_limit: the basins' first cap and jump limit (:mod:`sim_core.basins.basin`).
    """

    psi0: float
    fixed_leg: LegControl | None
    points: tuple[SweepPoint, ...]
    in_place_zeta0: tuple[float, ...]
    basin_grid: BasinGrid | None
    basin_jumps: int
    basin_jump_limit: int | None = None

    @property
    def zeta0(self) -> np.ndarray:
        return np.array([p.zeta0 for p in self.points])

    @property
    def max_abs_eigenvalue(self) -> np.ndarray:
        return np.array([math.nan if p.gait is None else p.gait.max_abs_eigenvalue for p in self.points])

    @property
    def climb_per_jump(self) -> np.ndarray:
        return np.array([p.climb_per_jump for p in self.points])

    @property
    def basin_area(self) -> np.ndarray:
        return np.array([math.nan if p.basin_area is None else p.basin_area for p in self.points])

    @property
    def basin_undecided(self) -> np.ndarray:
        """Cells of each basin neither converged nor failed within the jump limit (NaN: no basin)."""
        return np.array([math.nan if p.basin_undecided is None else p.basin_undecided for p in self.points])

    def to_dict(self) -> dict:
        """The ``parkour sweep --json`` contract."""
        grid = self.basin_grid
        return {
            "psi0_deg": round(math.degrees(self.psi0), 9),
            "fixed_leg": None
            if self.fixed_leg is None
            else {"psi0_deg": self.fixed_leg.psi0_deg, "zeta0": self.fixed_leg.zeta0},
            "points": [p.to_dict() for p in self.points],
            "in_place_zeta0": list(self.in_place_zeta0),
            "basin": None
            if grid is None
            else {
                "xdot_range": list(grid.xdot_range),
                "ydot_range": list(grid.ydot_range),
                "grid": grid.cells,
                "jumps": self.basin_jumps,
                "jump_limit": self.basin_jump_limit or self.basin_jumps,
            },
        }


def sweep_schedule(psi0: float, zeta0: float, fixed_leg: LegControl | None) -> ControlSchedule:
    """The schedule at one point of a sweep: symmetric, or ``[fixed leg, swept leg]``."""
    swept = LegControl(psi0, zeta0)
    return ControlSchedule.of(swept) if fixed_leg is None else ControlSchedule.of(fixed_leg, swept)


def zeta0_values(low: float, high: float, steps: int) -> np.ndarray:
    """``steps`` evenly spaced zeta0 in [low, high], validated."""
    low = check_range("zeta0_range", low, 0.0, 1.0)
    high = check_range("zeta0_range", high, 0.0, 1.0)
    if not low < high:
        raise ParameterError("zeta0_range", f"must be a non-empty interval with low < high, got [{low:g}, {high:g}]")
    if isinstance(steps, bool) or int(steps) != steps or not 2 <= steps <= MAX_STEPS:
        raise ParameterError("steps", f"must be an integer in [2, {MAX_STEPS}], got {steps!r}")
    return np.linspace(low, high, int(steps))


def energy_sweep(
    model: ModelParams,
    psi0: float,
    zeta0s: Sequence[float],
    *,
    fixed_leg: LegControl | None = None,
    guess=None,
    basin_grid: BasinGrid | None = None,
    basin_jumps: int = DEFAULT_JUMPS,
    basin_tolerance: float = DEFAULT_TOLERANCE,
    basin_jump_limit: int | None = None,
    chunk_map: ChunkMap = in_process,
    progress: Progress | None = None,
) -> EnergySweep:
    """Follow the gait over ``zeta0s`` (in the given order) by continuation.

    Args:
        psi0: the swept leg's angle [rad].
        fixed_leg: hold this leg and sweep the other (period 2); None sweeps both legs.
        guess: section state to seed the first solve; default: the most stable gait a search
            finds at the first zeta0 that has one.
        basin_grid: if given, each gait's basin area on this grid (:mod:`sim_core.basins.basin`).
        basin_jumps, basin_jump_limit: the basins' first cap, and the limit up to which undecided
            cells are continued (None: ``basin_jumps``).
        chunk_map: runs the basins, one chunk per gait (:mod:`sim_core.chunks`).
        progress: called as ``progress(done, total)`` after each gait and each basin.
    """
    zeta0s = [check_range("zeta0", z, 0.0, 1.0) for z in zeta0s]
    if not zeta0s:
        raise ParameterError("zeta0", "the sweep needs at least one zeta0")
    LegControl(psi0, zeta0s[0])  # validates psi0 before any work
    basin_jump_limit = check_jump_limit(basin_jump_limit, basin_jumps)
    period = 1 if fixed_leg is None else 2
    seed = None if guess is None else np.asarray(guess, dtype=float)
    total = len(zeta0s) * (2 if basin_grid is not None else 1)
    gaits = []
    for done, zeta0 in enumerate(zeta0s, start=1):
        gait = _continue(model, sweep_schedule(psi0, zeta0, fixed_leg), period, seed)
        if gait is not None:
            seed = gait.state
        gaits.append(gait)
        if progress is not None:
            progress(done, total)
    areas: list[float | None] = [None] * len(zeta0s)
    undecided: list[int | None] = [None] * len(zeta0s)
    if basin_grid is not None:
        # One chunk per gait: the basins are independent, so a cluster runs them side by side.
        found = [i for i, gait in enumerate(gaits) if gait is not None]
        starts = basin_grid.states()
        arguments = [
            (
                model,
                sweep_schedule(psi0, zeta0s[i], fixed_leg),
                gaits[i].orbit,
                starts,
                basin_jumps,
                basin_tolerance,
                basin_jump_limit,
            )
            for i in found
        ]
        offset = len(zeta0s) + len(zeta0s) - len(found)

        def basin_progress(done: int, _total: int) -> None:
            if progress is not None:
                progress(offset + done, total)

        for i, (jumps_to_converge, failure, _, _) in zip(
            found, chunk_map(converge_states, arguments, basin_progress), strict=True
        ):
            converged = jumps_to_converge != NOT_CONVERGED
            areas[i] = float(np.count_nonzero(converged)) * basin_grid.cell_area
            undecided[i] = int(np.count_nonzero(~converged & (failure == OK)))
    points = tuple(
        SweepPoint(zeta0, LegControl(psi0, zeta0).stored_energy(model.alpha), gait, area, left)
        for zeta0, gait, area, left in zip(zeta0s, gaits, areas, undecided, strict=True)
    )
    return EnergySweep(
        psi0=psi0,
        fixed_leg=fixed_leg,
        points=points,
        in_place_zeta0=tuple(_in_place_crossings(model, psi0, fixed_leg, points, period)),
        basin_grid=basin_grid,
        basin_jumps=basin_jumps,
        basin_jump_limit=basin_jump_limit,
    )


def find_in_place_zeta0(
    model: ModelParams, psi0: float, *, zeta0_range: tuple[float, float] = (0.8, 0.99), steps: int = 12, guess=None
) -> float:
    """The zeta0 of jumping in place for symmetric legs at ``psi0`` (the largest one in range).

    Raises :class:`ParameterError` if the climb does not change sign over ``zeta0_range``.
    """
    sweep = energy_sweep(model, psi0, zeta0_values(*zeta0_range, steps), guess=guess)
    if not sweep.in_place_zeta0:
        raise ParameterError(
            "zeta0_range", f"no zeta0 of jumping in place in [{zeta0_range[0]:g}, {zeta0_range[1]:g}] at this psi0"
        )
    return max(sweep.in_place_zeta0)


def _continue(model, schedule, period, seed) -> FixedPoint | None:
    """The gait from the neighbour's state; a gait search when there is no neighbour yet."""
    try:
        return gait_of(model, schedule, period, seed)
    except FixedPointNotFound:
        return None


def _in_place_crossings(model, psi0, fixed_leg, points, period) -> list[float]:
    """Brent's method on ``climb(zeta0)`` between neighbours whose climbs differ in sign."""
    from scipy.optimize import brentq  # loaded when first needed, as in fixed_points

    crossings = []
    for left, right in itertools.pairwise(points):
        if left.gait is None or right.gait is None:
            continue
        if not left.climb_per_jump * right.climb_per_jump < 0.0:
            continue

        def climb(zeta0: float, seed=left.gait.state) -> float:
            gait = find_fixed_point(model, sweep_schedule(psi0, zeta0, fixed_leg), period, seed)
            return gait.climb_per_period / gait.period

        try:
            crossings.append(float(brentq(climb, left.zeta0, right.zeta0, xtol=IN_PLACE_XTOL)))
        except FixedPointNotFound:
            continue  # the branch breaks between the neighbours; no crossing to report
    return crossings
