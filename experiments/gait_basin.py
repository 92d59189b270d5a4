"""A gait's basin of attraction as one study (docs/model.md §5): find the gait, place the window
of section states around it unless one is given, and run every cell of the grid through the map.

The one orchestration behind ``parkour basin`` and the service's basin job: both check the whole
spec before the (slow) gait search, and both default the window to the gait's state ± 1.5.
"""

from __future__ import annotations

from sim_core.basins.basin import Basin, check_convergence_test, compute_basin
from sim_core.basins.grid import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid
from sim_core.chunks import ChunkMap, Progress, in_process
from sim_core.model.controls import ControlSchedule
from sim_core.model.params import ModelParams
from sim_core.section.gait_search import gait_of

_PLACEHOLDER_WINDOW = ((-2.0, -1.0), (-1.0, 1.0))  # stands in for a default range while the spec is checked


def gait_basin(
    model: ModelParams,
    schedule: ControlSchedule,
    *,
    period: int | None = None,
    guess: tuple[float, float] | None = None,
    grid: int = 100,
    xdot_range: tuple[float, float] | None = None,
    ydot_range: tuple[float, float] | None = None,
    max_jumps: int = DEFAULT_JUMPS,
    tolerance: float = DEFAULT_TOLERANCE,
    jump_limit: int | None = None,
    chunk_map: ChunkMap = in_process,
    progress: Progress | None = None,
) -> Basin:
    """The basin of the gait of ``schedule`` (:func:`sim_core.section.gait_search.gait_of`: from ``guess``,
    else a grid search) on ``grid`` x ``grid`` cells; the answer holds the gait (``.gait``) and the
    window run (``.grid``).

    Args:
        period: the gait's period [jumps]; default the schedule's length.
        guess: a section state (xdot, ydot) [sqrt(g l0)] near the gait, or None to search.
        xdot_range, ydot_range: the window (low, high) [sqrt(g l0)]; each None: the gait's state ± 1.5.
        max_jumps, tolerance: a cell converges if its orbit comes within ``tolerance`` of the gait's
            orbit in at most ``max_jumps`` jumps.
        jump_limit: cells undecided after ``max_jumps`` go on, the cap doubled each round, up to this
            many jumps (None: ``max_jumps``; :func:`sim_core.basins.basin.compute_basin`).

    Raises:
        ParameterError: naming the field, before any search, for a bad window, grid or convergence test.
        NoGaitFound: no gait of these controls (callers name it in their own terms).
    """
    placeholder_x, placeholder_y = _PLACEHOLDER_WINDOW
    BasinGrid(xdot_range or placeholder_x, ydot_range or placeholder_y, grid)
    check_convergence_test(max_jumps, tolerance, jump_limit)
    gait = gait_of(model, schedule, period, guess)
    around = BasinGrid.around(gait.state, grid)
    cells = BasinGrid(xdot_range or around.xdot_range, ydot_range or around.ydot_range, grid)
    return compute_basin(
        model,
        schedule,
        gait,
        cells,
        max_jumps=max_jumps,
        tolerance=tolerance,
        jump_limit=jump_limit,
        chunk_map=chunk_map,
        progress=progress,
    )
