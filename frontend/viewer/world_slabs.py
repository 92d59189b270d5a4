"""A world's sides as the 3D view draws them (docs/model.md §8): pure geometry, no viser.

Each listed segment of a side is a slab: a thin box along the segment, at its inclination, its
inner face on the segment (the box lies outside the chute), coloured by its friction; the vertical
continuations (the model's ``mu``) are slabs too, from the floor to the first vertex and from the
last vertex up :data:`ABOVE_TOP` more. Scene frame as :mod:`frontend.viewer.geometry`: model ``x``
is scene ``x``, model ``y`` is scene ``z``, scene ``y`` is depth; lengths in metres (the world's
``l0`` units times the robot's leg length).

Colours (:func:`friction_color`, the legend :data:`LEGEND`): no grip (``mu`` 0) pale grey-blue,
gripping segments (footholds) from amber at low ``mu`` to green at :data:`FULL_GRIP_MU` and more,
no slip (``inf``) dark green.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.world.world import SIDES, World

SLAB_THICKNESS = 0.03  # [m] as the parallel walls (scene.WALL_THICKNESS)
SLAB_DEPTH = 0.35  # [m] (scene.DEPTH)
ABOVE_TOP = 1.5  # [m] the continuation drawn above each side's last vertex
FULL_GRIP_MU = 1.5  # friction at and above which a foothold is drawn full green
NO_GRIP = (178, 190, 205)
LOW_GRIP = np.array([235, 170, 40])
HIGH_GRIP = np.array([60, 170, 75])
NO_SLIP = (25, 110, 50)
LEGEND = (
    "**World:** grey-blue: no grip (mu 0) · footholds amber (mu → 0) to green (mu ≥ "
    f"{FULL_GRIP_MU:g}) · dark green: no slip"
)


def friction_color(mu: float) -> tuple[int, int, int]:
    """A segment's colour by its friction coefficient (resolved: no NaN)."""
    if mu == 0.0:
        return NO_GRIP
    if math.isinf(mu):
        return NO_SLIP
    share = min(mu / FULL_GRIP_MU, 1.0)
    r, g, b = (LOW_GRIP + share * (HIGH_GRIP - LOW_GRIP)).round().astype(int)
    return int(r), int(g), int(b)


@dataclass(frozen=True)
class Slab:
    """One box of a drawn world: ``name`` (its node under ``/chute/world/``), ``position`` (its
    centre) [m], ``wxyz`` (its rotation about scene ``y``), ``dimensions`` (thickness, depth,
    length) [m], ``color``, and ``mu`` (its friction; NaN for a continuation drawn as the walls)."""

    name: str
    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]
    dimensions: tuple[float, float, float]
    color: tuple[int, int, int]
    mu: float

    @property
    def foothold(self) -> bool:
        """A listed segment with grip."""
        return self.mu > 0.0  # NaN (a continuation) is not


def slab(name: str, start, end, side: str, color, mu: float) -> Slab:
    """The slab along the segment ``start`` → ``end`` (model-plane points [m], ``y`` up) of ``side``."""
    (ax, ay), (bx, by) = start, end
    dx, dy = bx - ax, by - ay
    length = math.hypot(dx, dy)
    tx, ty = dx / length, dy / length
    out = (-ty, tx) if side == "left" else (ty, -tx)  # away from the chute
    half = 0.5 * SLAB_THICKNESS
    centre = (0.5 * (ax + bx) + half * out[0], 0.5 * (ay + by) + half * out[1])
    angle = math.atan2(dx, dy)  # turns the box's z (its length) onto the segment, about scene y
    wxyz = (math.cos(0.5 * angle), 0.0, math.sin(0.5 * angle), 0.0)
    return Slab(name, (centre[0], 0.0, centre[1]), wxyz, (SLAB_THICKNESS, SLAB_DEPTH, length), color, mu)


def world_slabs(world: World, leg_length: float, model_mu: float) -> tuple[Slab, ...]:
    """The slabs of ``world`` (``l0`` units) at leg length ``leg_length`` [m], its open frictions
    resolved with ``model_mu``: per side its floor continuation (where the first vertex is above
    the floor), its segments bottom to top, and its continuation above."""
    slabs = []
    for name in SIDES:
        side = world.side(name)
        points = side.points * leg_length
        friction = side.friction(model_mu)
        (x0, y0), (xn, yn) = points[0], points[-1]
        if y0 > 1e-9:
            slabs.append(slab(f"{name}_below", (x0, 0.0), (x0, y0), name, friction_color(model_mu), math.nan))
        for k in range(side.segments):
            mu = float(friction[k])
            slabs.append(slab(f"{name}_{k}", points[k], points[k + 1], name, friction_color(mu), mu))
        slabs.append(slab(f"{name}_above", (xn, yn), (xn, yn + ABOVE_TOP), name, friction_color(model_mu), math.nan))
    return tuple(slabs)


def world_width(world: World, leg_length: float) -> tuple[float, float]:
    """[m] the floor's ends: the sides' ``x`` at the floor."""
    return world.left.x_at(0.0) * leg_length, world.right.x_at(0.0) * leg_length


def world_words(world: World, leg_length: float) -> str:
    """``world`` as the view's header says it (leg length ``leg_length`` [m]): its name and how far
    apart its sides are [m], narrowest to widest. The gap is linear between the sides' vertices and
    constant past them, so its extremes are at the vertices' heights."""
    heights = np.union1d(world.left.points[:, 1], world.right.points[:, 1])
    right = np.interp(heights, world.right.points[:, 1], world.right.points[:, 0])
    gaps = (right - np.interp(heights, world.left.points[:, 1], world.left.points[:, 0])) * leg_length
    narrowest, widest = f"{gaps.min():.2f}", f"{gaps.max():.2f}"
    name = f"world {world.name!r}" if world.name else "an unnamed world"
    apart = narrowest if narrowest == widest else f"{narrowest} m to {widest}"
    return f"{name}, sides {apart} m apart"
