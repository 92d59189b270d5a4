"""Pure geometry of the 3D view: the BowLeg's curve, its colour by stored energy, the ruler.

The model is planar; the scene puts its plane upright: model ``x`` (across the chute) is scene
``x``, model ``y`` (up) is scene ``z``, and scene ``y`` is depth. All lengths in metres.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core import LegControl, PhysicalParams

BOW_ARC = 1.02  # the bow's arc length over l0: a BowLeg is bent a little even at full length
BOW_POINTS = 13
FULL_ENERGY_ZETA = 0.8  # [l0] the colour scale saturates at this compression (the slider's lower end)
RELAXED = np.array([30, 110, 230])  # blue: no energy stored
LOADED = np.array([225, 30, 30])  # red: the most the sliders can store


def to_scene(x, y) -> np.ndarray:
    """Model-plane points (arrays or floats) to scene points, shape (..., 3)."""
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    return np.stack([x, np.zeros_like(x), y], axis=-1)


def polyline_segments(points: np.ndarray) -> np.ndarray:
    """A polyline's model-plane points (n, 2) as viser line segments, shape (n - 1, 2, 3)."""
    scene = to_scene(points[:, 0], points[:, 1])
    return np.stack([scene[:-1], scene[1:]], axis=1)


def bow_leg(hip: tuple[float, float], foot: tuple[float, float], leg_length: float) -> np.ndarray:
    """The BowLeg from hip to foot, shape (BOW_POINTS, 2).

    A bow of fixed arc length ``BOW_ARC * l0`` drawn as a shallow arc over the chord: the shorter
    the chord (the more compressed the leg), the deeper the bow. Sagitta of a shallow arc:
    ``h = sqrt(3 c (s - c) / 8)`` for chord ``c`` and arc length ``s``. The bow bulges downward.
    """
    hip_point, foot_point = np.asarray(hip, dtype=float), np.asarray(foot, dtype=float)
    chord = foot_point - hip_point
    length = float(np.hypot(*chord))
    s = np.linspace(0.0, 1.0, BOW_POINTS)
    line = hip_point + s[:, None] * chord
    if length == 0.0:
        return line
    arc = BOW_ARC * leg_length
    sagitta = math.sqrt(max(3.0 * length * (arc - length) / 8.0, 0.0))
    normal = np.array([-chord[1], chord[0]]) / length
    if normal[1] > 0:
        normal = -normal
    return line + (sagitta * np.sin(np.pi * s))[:, None] * normal


def stored_energy(zeta: float, robot: PhysicalParams) -> float:
    """[J] spring energy of a leg of length ``zeta`` [m]: ``k (l0 - zeta)^2 / 2``, 0 when extended."""
    compression = max(robot.leg_length - zeta, 0.0)
    return 0.5 * robot.stiffness * compression**2


def energy_color(zeta: float, robot: PhysicalParams) -> tuple[int, int, int]:
    """The leg's colour: blue when relaxed, red at ``FULL_ENERGY_ZETA`` compression or more."""
    full = stored_energy(FULL_ENERGY_ZETA * robot.leg_length, robot)
    share = min(stored_energy(zeta, robot) / full, 1.0) if math.isfinite(zeta) else 0.0
    r, g, b = (RELAXED + share * (LOADED - RELAXED)).round().astype(int)
    return int(r), int(g), int(b)


def idle_foot(body: tuple[float, float], leg: LegControl, wall: int, robot: PhysicalParams) -> tuple[float, float]:
    """Where a leg held at its touchdown controls, reaching for ``wall`` (-1 left, +1 right), ends."""
    length = leg.zeta0 * robot.leg_length
    return body[0] + wall * length * math.cos(leg.psi0), body[1] - length * math.sin(leg.psi0)


def ruler_ticks(top: float, *, minor: float = 0.05, major: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """Tick heights [m] from 0 to ``top``: ``(all ticks, major ticks)``; majors get labels."""
    ticks = np.arange(0.0, top + 1e-9, minor)
    majors = ticks[np.isclose(np.mod(ticks + 1e-9, major), 0.0, atol=1e-6)]
    return ticks, majors
