"""A world's sides as the compiled kernels read them, and the touchdown in closed form
(docs/model.md §8).

:func:`pack` turns a :class:`~sim_core.world.world.World` and the model's ``mu`` into a
:class:`SideArrays` record: every side's vertices, each segment's friction and inclination
``beta``, indexed by ``segment + 1`` so that the continuation below the first vertex (segment
``-1``) is column 0. Sides are numbered ``0`` (left) and ``1`` (right).

The stance frame of a side is the flipped frame of docs/model.md §2: the stance side is the
left one. A left side's stance frame is the wall frame (``mirror = +1``), a right side's is the
wall frame with ``x -> -x`` (``mirror = -1``); ``beta`` is stored in each side's own stance
frame. The other side, the one the flight aims at, is read through the same mirror.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from sim_core._jit import kernel
from sim_core.world.world import SIDES, World, inclinations

LEFT, RIGHT = 0, 1  # side indices in the kernels (JSON says "left" and "right")
SIDE_NAMES = SIDES  # in the kernels' order
FLIGHT_TIME_CAP = 10.0  # [sqrt(l0/g)]: a flight this long met no side (docs/model.md §8, `no_touchdown`)
SAME_TIME = 1e-12  # [sqrt(l0/g)]: crossings closer in time than this are a tie, won by the segment above


class SideArrays(NamedTuple):
    """A world as the kernels take it (one typed argument, read by field).

    Attributes:
        points: shape (2, N, 2), each side's vertices ``(x, y)`` [l0] in wall coordinates,
            padded past its count with its last vertex.
        counts: shape (2,), each side's vertex count ``n`` (segments ``-1 .. n - 1``).
        friction: shape (2, N + 1), the friction of segment ``i`` at column ``i + 1`` (the
            continuations: the model's ``mu``).
        beta: shape (2, N + 1), the inclination [rad] of segment ``i``'s inward normal in its
            side's stance frame, at column ``i + 1`` (continuations: 0).
    """

    points: np.ndarray
    counts: np.ndarray
    friction: np.ndarray
    beta: np.ndarray


def pack(world: World, model_mu: float) -> SideArrays:
    """The kernels' record of ``world`` with ``model_mu`` where the world leaves friction open."""
    sides = (world.left, world.right)
    widest = max(side.points.shape[0] for side in sides)
    points = np.empty((2, widest, 2))
    friction = np.full((2, widest + 1), float(model_mu))
    beta = np.zeros((2, widest + 1))
    counts = np.empty(2, dtype=np.int64)
    for index, (side, name) in enumerate(zip(sides, SIDE_NAMES, strict=True)):
        n = side.points.shape[0]
        counts[index] = n
        points[index, :n] = side.points
        points[index, n:] = side.points[-1]
        friction[index, 1:n] = side.friction(model_mu)
        beta[index, 1:n] = inclinations(side.points, name)
    return SideArrays(points, counts, friction, beta)


@kernel
def segment_at(sides, side, y):
    """The segment of ``side`` at height ``y`` [l0]: ``-1`` below the first vertex, ``n - 1`` at
    or above the last; a height exactly at a vertex belongs to the segment above it."""
    points = sides.points[side]
    last = sides.counts[side] - 1
    if y < points[0, 1]:
        return -1
    if y >= points[last, 1]:
        return last
    low, high = 0, last  # points[low, 1] <= y < points[high, 1]
    while high - low > 1:
        middle = (low + high) // 2
        if points[middle, 1] <= y:
            low = middle
        else:
            high = middle
    return low


@kernel
def side_x(sides, side, y):
    """The ``x`` [l0, wall coordinates] of ``side`` at height ``y`` (vertical past its ends)."""
    points = sides.points[side]
    segment = segment_at(sides, side, y)
    if segment < 0:
        return points[0, 0]
    if segment >= sides.counts[side] - 1:
        return points[segment, 0]
    xa, ya = points[segment, 0], points[segment, 1]
    xb, yb = points[segment + 1, 0], points[segment + 1, 1]
    return xa + (y - ya) * (xb - xa) / (yb - ya)


@kernel
def _first_root(a, b, c, after):
    """The roots ``t > after`` of ``a t^2 + b t + c = 0``, smaller first, NaN where absent; a
    double root (a tangent touch) counts."""
    nan = math.nan
    if a == 0.0:
        if b == 0.0:
            return nan, nan
        t = -c / b
        return (t, nan) if t > after else (nan, nan)
    discriminant = b * b - 4.0 * a * c
    if discriminant < 0.0:
        return nan, nan
    # the stable pair: no cancellation between b and the root
    q = -0.5 * (b + math.copysign(math.sqrt(discriminant), b))
    first, second = (q / a, c / q) if q != 0.0 else (0.0, 0.0)
    if first > second:
        first, second = second, first
    if first > after:
        return first, second
    if second > after:
        return second, nan
    return nan, nan


@kernel
def first_crossing(sides, side, mirror, x0, y0, vx, vy):
    """When and where a point on the parabola ``(x0 + vx t, y0 + vy t - t^2/2)`` (the coming
    foot, in the stance frame ``mirror``) first reaches ``side``'s polyline: ``(t, segment)``,
    ``t = inf`` if never. Per segment the crossing is a quadratic in ``t``; a root counts where
    the foot's height lies on that segment (``[y_a, y_b)``: a vertex belongs to the segment above;
    below the first vertex and above the last, the vertical continuations)."""
    points = sides.points[side]
    n = sides.counts[side]
    best_t, best_segment = math.inf, -2
    apex = y0 + 0.5 * vy * vy if vy > 0.0 else y0  # the foot never rises above it
    for segment in range(-1, n):
        if segment >= 0 and points[segment, 1] > apex:
            break  # this segment and every one above start higher than the foot ever gets
        if segment == -1:  # x = x_0 below y_0
            xa, ya, slope = mirror * points[0, 0], points[0, 1], 0.0
            y_low, y_high = -math.inf, points[0, 1]
        elif segment == n - 1:  # x = x_last from y_last up
            xa, ya, slope = mirror * points[n - 1, 0], points[n - 1, 1], 0.0
            y_low, y_high = points[n - 1, 1], math.inf
        else:
            xa, ya = mirror * points[segment, 0], points[segment, 1]
            xb, yb = mirror * points[segment + 1, 0], points[segment + 1, 1]
            slope = (xb - xa) / (yb - ya)  # dx/dy along the segment
            y_low, y_high = ya, yb
        # x(t) - [xa + (y(t) - ya) slope] = 0, a quadratic in t
        a = 0.5 * slope
        b = vx - vy * slope
        c = x0 - xa - (y0 - ya) * slope
        for root in _first_root(a, b, c, 0.0):
            if not math.isfinite(root):
                continue
            y = y0 + vy * root - 0.5 * root * root
            if y_low <= y < y_high:
                # segments come bottom to top: in a tie the later one is the segment above
                if root < best_t - SAME_TIME or abs(root - best_t) <= SAME_TIME:
                    best_t, best_segment = root, segment
                break  # the later root of this segment is no first crossing
    return best_t, best_segment
