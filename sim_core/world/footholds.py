"""Footholds as geometry (docs/model.md §8): a segment's inclination ``beta`` and a side laid out as
footholds — short gripping segments at given inclinations — joined by segments without grip
(``mu = 0``). The staircase (:mod:`sim_core.world.named`) and random footholds
(:mod:`sim_core.world.random_world`) are both laid out here.

``beta`` is the angle of a segment's normal pointing into the chute, from ``+x`` counter-clockwise,
after the flip that maps the right side onto the left: ``0`` for a vertical wall, ``> 0`` when the
surface faces upward, ``< 0`` when it faces downward.
"""

from __future__ import annotations

import numpy as np

from sim_core.world.world import SIDES, Side

NO_GRIP = 0.0


def foothold_side(
    side: str,
    wall_x: float,
    lengths: np.ndarray,
    betas: np.ndarray,
    mu: np.ndarray,
    gaps: np.ndarray,
    *,
    start: float = 0.0,
    top: float = 0.0,
) -> Side:
    """A side of ``k`` footholds, bottom to top, each centred on the wall line ``x = wall_x``.

    Foothold ``i`` rises ``lengths[i] cos(betas[i])`` at inclination ``betas[i]``; a segment without
    grip joins it to foothold ``i + 1``, which starts ``gaps[i]`` higher. Below the first foothold
    (if ``start > 0``) and above the last one (up to ``top``, if higher) the side is a vertical
    segment without grip on the wall line.

    Args:
        side: ``"left"`` or ``"right"`` (the right side's footholds are the left's mirrored).
        wall_x: the wall line's ``x`` [l0] (``-d_hat/2`` on the left, ``+d_hat/2`` on the right).
        lengths: shape (k,), the footholds' lengths [l0], > 0.
        betas: shape (k,), their inclinations [rad], in (-90°, 90°).
        mu: shape (k,), their friction coefficients.
        gaps: shape (k - 1,), the rise [l0] from one foothold's top to the next one's bottom, > 0.
        start: the first foothold's bottom ``y`` [l0]; from ``y = 0`` up to it, no grip.
        top: the side's last vertex ``y`` [l0] if the footholds end below it.
    """
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    across = np.asarray(lengths) * np.sin(betas) * (-1.0 if side == "left" else 1.0)
    rises = np.asarray(lengths) * np.cos(betas)
    bottoms = start + np.concatenate(([0.0], np.cumsum(rises[:-1] + gaps)))
    vertices = np.empty((2 * len(rises), 2))
    vertices[0::2] = np.column_stack((wall_x - across / 2, bottoms))
    vertices[1::2] = np.column_stack((wall_x + across / 2, bottoms + rises))
    friction = np.full(2 * len(rises) - 1, NO_GRIP)
    friction[0::2] = mu
    if start > 0:
        vertices = np.vstack(([wall_x, 0.0], vertices))
        friction = np.concatenate(([NO_GRIP], friction))
    if top > vertices[-1, 1]:
        vertices = np.vstack((vertices, [wall_x, top]))
        friction = np.concatenate((friction, [NO_GRIP]))
    return Side(vertices, friction)


def holds_below(lengths: np.ndarray, betas: np.ndarray, gaps: np.ndarray, height: float, start: float = 0.0) -> int:
    """How many of the footholds, laid out as :func:`foothold_side` lays them from ``start``, end
    at or below ``height`` [l0] (a prefix: the tops increase). ``gaps`` has one entry per foothold
    (the last one unused)."""
    rises = np.asarray(lengths) * np.cos(betas)
    tops = start + np.cumsum(rises) + np.concatenate(([0.0], np.cumsum(gaps[: len(rises) - 1])))
    return int(np.searchsorted(tops, height, side="right"))
