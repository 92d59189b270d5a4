"""A world as data (docs/model.md §8): two sides, each a polyline bottom to top with a friction
coefficient per segment, in wall coordinates and ``l0`` units.

A side's segments are numbered ``0 .. n - 2`` between its ``n`` vertices; ``-1`` is the vertical
continuation below the first vertex and ``n - 1`` the one above the last (both with the model's
``mu``). A segment's ``mu`` is a number ``>= 0``, ``inf`` (no slip) or NaN (the model's ``mu``,
resolved when the world meets a model: :meth:`Side.friction`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SIDES = ("left", "right")


@dataclass(frozen=True, eq=False)
class Side:
    """One side of the chute.

    Attributes:
        points: shape (n, 2), n >= 2, vertices ``(x, y)`` [l0] in wall coordinates, ``y``
            strictly increasing.
        mu: shape (n - 1,), each segment's friction coefficient (``inf``: no slip; NaN: the
            model's ``mu``).
    """

    points: np.ndarray
    mu: np.ndarray

    @property
    def segments(self) -> int:
        """The listed segments' count, ``n - 1`` (the continuations not counted)."""
        return self.points.shape[0] - 1

    def friction(self, model_mu: float) -> np.ndarray:
        """Every segment's friction with the model's ``mu`` put where the world leaves it open."""
        return np.where(np.isnan(self.mu), model_mu, self.mu)

    def x_at(self, y: float) -> float:
        """The side's ``x`` [l0] at height ``y`` [l0] (a vertical continuation past its ends)."""
        return float(np.interp(y, self.points[:, 1], self.points[:, 0]))


@dataclass(frozen=True, eq=False)
class World:
    """A chute: its ``left`` and ``right`` sides and a ``name`` for people (``""``: unnamed)."""

    left: Side
    right: Side
    name: str = ""

    @property
    def top(self) -> float:
        """Where the chute as drawn ends [l0]: the lower of the two sides' last vertices (above
        it both sides only go on as vertical walls)."""
        return float(min(self.left.points[-1, 1], self.right.points[-1, 1]))

    def side(self, name: str) -> Side:
        return self.left if name == "left" else self.right


def inclinations(points: np.ndarray, side: str) -> np.ndarray:
    """Each listed segment's ``beta`` [rad], shape (n - 1,), for a side's vertices ``points``
    (shape (n, 2), ``y`` increasing) on side ``side`` (``"left"`` or ``"right"``), in that side's
    stance frame (docs/model.md §8): for a left segment from ``a`` to ``b``, tangent
    ``t = (b - a)/L``, normal ``n = (t_y, -t_x)``, ``beta = atan2(n_y, n_x)``; a right segment is
    mirrored ``x -> -x`` first. 0 on a vertical wall, ``> 0`` where the surface faces upward.

    >>> from math import degrees
    >>> [round(degrees(b), 6) for b in inclinations(np.array([[0.0, 0.0], [0.0, 1.0], [-1.0, 2.0]]), "left")]
    [0.0, 45.0]
    """
    step = np.diff(np.asarray(points, dtype=float), axis=0)
    across = step[:, 0] if side == "left" else -step[:, 0]
    # n = (t_y, -t_x) up to the positive length: atan2 needs no normalising; + 0.0: a vertical
    # segment's beta is 0, not -0
    return np.arctan2(-across, step[:, 1]) + 0.0


def parallel(d_hat: float, height: float = 1.0, mu: float = math.nan) -> World:
    """Two vertical walls ``d_hat`` apart (each one segment from ``y = 0`` to ``height``; the
    continuations go on past its ends): docs/model.md §2's chute as a world."""
    left = Side(np.array([[-d_hat / 2, 0.0], [-d_hat / 2, height]]), np.array([mu]))
    right = Side(np.array([[d_hat / 2, 0.0], [d_hat / 2, height]]), np.array([mu]))
    return World(left, right, "parallel")
