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

    def side(self, name: str) -> Side:
        return self.left if name == "left" else self.right


def inclinations(points: np.ndarray, mirror: float) -> np.ndarray:
    """Each segment's ``beta`` [rad] of a side whose stance frame maps ``x`` to ``mirror * x``
    (``+1`` for the left side, ``-1`` for the right): for a (mirrored) segment from ``a`` to
    ``b``, ``t = (b - a)/|b - a|``, ``n = (t_y, -t_x)``, ``beta = atan2(n_y, n_x)`` (docs/model.md
    §8): 0 on a vertical wall, ``> 0`` where the surface faces upward."""
    delta = np.diff(points, axis=0) * np.array([mirror, 1.0])
    # n = (t_y, -t_x) up to the positive length: atan2 needs no normalising
    return np.arctan2(-delta[:, 0], delta[:, 1])


def parallel(d_hat: float, height: float = 1.0, mu: float = math.nan) -> World:
    """Two vertical walls ``d_hat`` apart (each one segment from ``y = 0`` to ``height``; the
    continuations go on past its ends): docs/model.md §2's chute as a world."""
    left = Side(np.array([[-d_hat / 2, 0.0], [-d_hat / 2, height]]), np.array([mu]))
    right = Side(np.array([[d_hat / 2, 0.0], [d_hat / 2, height]]), np.array([mu]))
    return World(left, right, "parallel")
