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
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    out = np.zeros((*np.broadcast_shapes(x.shape, y.shape), 3))
    out[..., 0], out[..., 2] = x, y
    return out


def polyline_segments(points: np.ndarray) -> np.ndarray:
    """A polyline's model-plane points (..., n, 2) as viser line segments, shape (..., n - 1, 2, 3)
    (leading axes: many polylines at once, e.g. one per frame)."""
    points = np.asarray(points, dtype=float)
    out = np.zeros((*points.shape[:-2], max(points.shape[-2] - 1, 0), 2, 3))
    out[..., 0, 0], out[..., 0, 2] = points[..., :-1, 0], points[..., :-1, 1]
    out[..., 1, 0], out[..., 1, 2] = points[..., 1:, 0], points[..., 1:, 1]
    return out


def bow_leg(hip: tuple[float, float], foot: tuple[float, float], leg_length: float) -> np.ndarray:
    """The BowLeg from hip to foot, shape (BOW_POINTS, 2).

    A bow of fixed arc length ``BOW_ARC * l0`` drawn as a shallow arc over the chord: the shorter
    the chord (the more compressed the leg), the deeper the bow. Sagitta of a shallow arc:
    ``h = sqrt(3 c (s - c) / 8)`` for chord ``c`` and arc length ``s``. The bow bulges downward.
    """
    hip_point = np.asarray(hip, dtype=float)
    return hip_point + bow_legs(np.asarray(foot, dtype=float) - hip_point, leg_length)


def bow_legs(chords: np.ndarray, leg_length: float) -> np.ndarray:
    """:func:`bow_leg` from the hip at (0, 0) to each foot ``chords`` (..., 2): shape (..., BOW_POINTS, 2)."""
    chords = np.asarray(chords, dtype=float)
    length = np.hypot(chords[..., 0], chords[..., 1])
    s = np.linspace(0.0, 1.0, BOW_POINTS)
    line = s[:, None] * chords[..., None, :]
    arc = BOW_ARC * leg_length
    sagitta = np.sqrt(np.maximum(3.0 * length * (arc - length) / 8.0, 0.0))
    bent = length > 0.0  # a zero chord is a point: no bow
    normal = np.stack([-chords[..., 1], chords[..., 0]], axis=-1) / np.where(bent, length, 1.0)[..., None]
    normal = np.where(normal[..., 1:] > 0, -normal, normal)
    bulge = np.where(bent, sagitta, 0.0)[..., None] * np.sin(np.pi * s)
    return line + bulge[..., None] * normal[..., None, :]


def stored_energy(zeta, robot: PhysicalParams):
    """[J] spring energy of a leg of length ``zeta`` [m] (or an array of them): ``k (l0 - zeta)^2 / 2``,
    0 when extended."""
    compression = np.maximum(robot.leg_length - np.asarray(zeta, dtype=float), 0.0)
    energy = 0.5 * robot.stiffness * compression**2
    return float(energy) if energy.ndim == 0 else energy


def energy_color(zeta: float, robot: PhysicalParams) -> tuple[int, int, int]:
    """The leg's colour: blue when relaxed, red at ``FULL_ENERGY_ZETA`` compression or more."""
    r, g, b = energy_colors(np.array([zeta]), robot)[0]
    return int(r), int(g), int(b)


def energy_colors(zeta: np.ndarray, robot: PhysicalParams) -> np.ndarray:
    """:func:`energy_color` of each leg length ``zeta`` (n,) [m]: shape (n, 3), uint8. NaN (legs unknown): relaxed."""
    zeta = np.asarray(zeta, dtype=float)
    full = stored_energy(FULL_ENERGY_ZETA * robot.leg_length, robot)
    known = np.isfinite(zeta)
    share = np.where(known, np.minimum(stored_energy(np.where(known, zeta, robot.leg_length), robot) / full, 1.0), 0.0)
    return (RELAXED + share[:, None] * (LOADED - RELAXED)).round().astype(np.uint8)


def idle_foot(body: tuple[float, float], leg: LegControl, wall: int, robot: PhysicalParams) -> tuple[float, float]:
    """Where a leg held at its touchdown controls, reaching for ``wall`` (-1 left, +1 right), ends."""
    length = leg.zeta0 * robot.leg_length
    return body[0] + wall * length * math.cos(leg.psi0), body[1] - length * math.sin(leg.psi0)


def ruler_ticks(
    top: float, *, minor: float = 0.05, major: float = 0.25, above: float = -math.inf
) -> tuple[np.ndarray, np.ndarray]:
    """Tick heights [m] from 0 to ``top`` (only those above ``above``): ``(all ticks, major
    ticks)``; majors get labels."""
    ticks = np.arange(0.0, top + 1e-9, minor)
    ticks = ticks[ticks > above + 1e-9]
    majors = ticks[np.isclose(np.mod(ticks + 1e-9, major), 0.0, atol=1e-6)]
    return ticks, majors
