"""The rules a world keeps (docs/model.md §8), checked in one place for world files, named and
random worlds: each side at least one and at most :data:`MAX_SEGMENTS` segments, finite
vertices with ``y`` strictly increasing, one friction coefficient per segment (``>= 0``, ``inf``
or NaN for the model's ``mu``), and the left side strictly left of the right one at every height.

An error is a :class:`~sim_core.model.errors.ParameterError` whose field names the side and the
point or segment (``"left.points[3]"``, ``"right.mu[2]"``) and whose message says the rule and the
value received. The checks work in whatever unit the numbers come in (a world file in metres is
checked before it is converted), so a message quotes the numbers as the user wrote them.
"""

from __future__ import annotations

import numpy as np

from sim_core.model.errors import ParameterError
from sim_core.world.world import SIDES, World

# A bound on a side's segments, so that a world file cannot make the kernels' per-segment search
# arbitrarily long; a foothold course 2 m tall needs a few dozen.
MAX_SEGMENTS = 256


def check_world(world: World) -> World:
    """``world`` itself if it keeps every rule of §8, else :class:`ParameterError` naming the first
    broken one (coordinates in ``l0``)."""
    for name in SIDES:
        side = world.side(name)
        check_side(name, np.asarray(side.points, dtype=float), np.asarray(side.mu, dtype=float))
    check_sides_apart(np.asarray(world.left.points, dtype=float), np.asarray(world.right.points, dtype=float))
    return world


def check_point_count(name: str, count: int) -> None:
    """A side has 2 to ``MAX_SEGMENTS + 1`` vertices (checked before a file's points are read)."""
    if not 2 <= count <= MAX_SEGMENTS + 1:
        raise ParameterError(
            f"{name}.points",
            f"must have 2 to {MAX_SEGMENTS + 1} points (1 to MAX_SEGMENTS = {MAX_SEGMENTS} segments), got {count}",
        )


def check_side(name: str, points: np.ndarray, mu: np.ndarray) -> None:
    """One side's own rules.

    Args:
        name: ``"left"`` or ``"right"``, for the error's field.
        points: shape (n, 2), the vertices ``(x, y)`` bottom to top (any length unit).
        mu: shape (n - 1,), each segment's friction (NaN: the model's ``mu``; ``inf``: no slip).
    """
    if points.ndim != 2 or points.shape[1] != 2:
        raise ParameterError(f"{name}.points", f"must be a list of (x, y) pairs, got shape {points.shape}")
    check_point_count(name, points.shape[0])
    for index, (x, y) in enumerate(points):
        for axis, value in (("x", x), ("y", y)):
            if not np.isfinite(value):
                raise ParameterError(f"{name}.points[{index}]", f"{axis} must be a finite number, got {value}")
        if index and not y > points[index - 1, 1]:
            raise ParameterError(
                f"{name}.points[{index}]",
                f"y must increase strictly bottom to top: {float(y)!r} after {float(points[index - 1, 1])!r}",
            )
    segments = points.shape[0] - 1
    if mu.shape != (segments,):
        got = mu.shape[0] if mu.ndim == 1 else f"shape {mu.shape}"
        raise ParameterError(f"{name}.mu", f"must have one entry per segment ({segments}), got {got}")
    for index, value in enumerate(mu):
        if value < 0:  # False for NaN (the model's mu) and for inf (no slip): both allowed
            raise ParameterError(f"{name}.mu[{index}]", f'must be >= 0, null or "inf", got {float(value)!r}')


def check_sides_apart(left: np.ndarray, right: np.ndarray) -> None:
    """At every height the left side is strictly left of the right one, else an error naming the
    lowest vertex where they cross or touch.

    Both sides are piecewise linear in ``y`` with their vertices as breakpoints and go on
    vertically past their ends, so their distance is linear between consecutive vertex heights of
    either side and constant beyond them: checking at every vertex height is exact.

    Args:
        left, right: shape (n, 2) and (m, 2), the sides' vertices, each already valid by
            :func:`check_side`.
    """
    heights = np.union1d(left[:, 1], right[:, 1])
    left_x = np.interp(heights, left[:, 1], left[:, 0])
    right_x = np.interp(heights, right[:, 1], right[:, 0])
    crossed = np.flatnonzero(~(left_x < right_x))  # NaN (from overflowing coordinates) counts as crossed
    if crossed.size == 0:
        return
    first = crossed[0]
    height = heights[first]
    on_left = np.flatnonzero(left[:, 1] == height)
    field = (
        f"left.points[{on_left[0]}]" if on_left.size else f"right.points[{np.flatnonzero(right[:, 1] == height)[0]}]"
    )
    raise ParameterError(
        field,
        f"the sides must not cross or touch: at y = {float(height)!r} the left side is at "
        f"x = {float(left_x[first])!r}, the right side at x = {float(right_x[first])!r} "
        "(the left must be strictly left of the right at every height)",
    )
