"""Which gait: a grid search for periodic gaits and :func:`gait_of`, the gait of a control schedule
(docs/model.md §4).

:func:`gait_of` is "the gait of these controls" that every command, the service, the 3D view
and the figures use: Levenberg–Marquardt (:func:`sim_core.section.fixed_points.find_fixed_point`) from a
guess when there is one, else the most stable gait a grid search (:func:`search_gaits`) finds.
"""

from __future__ import annotations

import numpy as np

from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import FixedPointNotFound, NoGaitFound
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError
from sim_core.section.fixed_points import FixedPoint, check_period, find_fixed_point

DEFAULT_GRID = (6, 6)  # guesses per axis (xdot, ydot) of a gait search


def search_gaits(
    model: ModelParams,
    schedule: ControlSchedule,
    period: int,
    *,
    xdot_range: tuple[float, float] = (-2.5, -0.25),
    ydot_range: tuple[float, float] = (-2.0, 2.0),
    grid: tuple[int, int] = DEFAULT_GRID,
) -> list[FixedPoint]:
    """Distinct fixed points of ``P^period`` found from a grid of guesses.

    Runs :func:`find_fixed_point` from each point of a ``grid`` over the given section
    ranges and keeps one representative per orbit. Sorted stable first, then by
    max |eigenvalue|. An empty list means no search converged — not that no gait exists.
    """
    period = check_period(schedule, period)
    if not (xdot_range[0] < xdot_range[1] < 0.0):
        raise ParameterError("xdot_range", f"must be an increasing pair below 0, got {xdot_range}")
    if not ydot_range[0] < ydot_range[1]:
        raise ParameterError("ydot_range", f"must be an increasing pair, got {ydot_range}")
    if min(grid) < 1 or max(grid) > 100:
        raise ParameterError("grid", f"each side must be in [1, 100], got {grid}")
    found: list[FixedPoint] = []
    for xdot in np.linspace(*xdot_range, grid[0]):
        for ydot in np.linspace(*ydot_range, grid[1]):
            try:
                gait = find_fixed_point(model, schedule, period, (xdot, ydot))
            except FixedPointNotFound:
                continue
            if not any(_same_orbit(gait, known, len(schedule)) for known in found):
                found.append(gait)
    return sorted(found, key=lambda gait: (not gait.stable, gait.max_abs_eigenvalue))


def gait_of(
    model: ModelParams,
    schedule: ControlSchedule,
    period: int | None = None,
    guess=None,
    *,
    grid: tuple[int, int] = DEFAULT_GRID,
    prefer_stable: bool = False,
) -> FixedPoint:
    """The gait of these controls: the one place that decides which fixed point a caller means.

    Args:
        period: n of ``P^n(q) = q`` [jumps], a multiple of the schedule's length; default: that
            length. The gait found reports its minimal period, which may divide n.
        guess: section state ``(xdot, ydot)`` [sqrt(g l0)] to start Levenberg–Marquardt from;
            None searches a ``grid`` of guesses (:func:`search_gaits`) and takes the most stable.
        grid: guesses per axis (xdot, ydot) of that search.
        prefer_stable: if the gait from ``guess`` does not converge or is unstable, search the
            grid instead (the 3D view: a person wants the gait the robot can walk). The grid's
            most stable gait is returned even when it is unstable.

    Raises:
        FixedPointNotFound: Levenberg–Marquardt did not converge from ``guess`` (the message
            says why); :class:`NoGaitFound` when a grid search found nothing.
        ParameterError: a bad ``period``, ``guess`` or ``grid``, naming the field.
    """
    period = check_period(schedule, len(schedule) if period is None else period)
    if guess is not None:
        try:
            gait = find_fixed_point(model, schedule, period, guess)
        except FixedPointNotFound:
            if not prefer_stable:
                raise
        else:
            if gait.stable or not prefer_stable:
                return gait
    gaits = search_gaits(model, schedule, period, grid=grid)
    if not gaits:
        raise NoGaitFound(schedule, period)
    return gaits[0]


def _same_orbit(a: FixedPoint, b: FixedPoint, schedule_length: int, tol: float = 1e-6) -> bool:
    """Whether ``a`` lies on ``b``'s orbit at the same phase of the control schedule."""
    if a.period != b.period:
        return False
    in_phase = b.orbit[::schedule_length]
    return bool(np.any(np.linalg.norm(in_phase - a.state, axis=1) <= tol))
