"""One-jump predictions of tracked touchdowns in a world (docs/model.md §8, docs/calibration.md):
:func:`~sim_core.calibration.calibrate.one_jump_predictions` for a run that climbed a world's
sides, not the parallel walls the Poincaré map assumes.

Each measured touchdown ``k - 1`` is taken as it was met — its side, its foot's height on that
side, its section state — and the model climbs one jump from it in the world
(:func:`sim_core.world.climb.climb_from_touchdown`, read as the map's orbit by
:func:`sim_core.world.climb.section_orbit`) to touchdown ``k``. As
:mod:`sim_core.calibration.touchdown_model` does between parallel walls, the leg the model jumps
with is the commanded one plus the leg's offset turned by the pitch, while the detector
(backend.robot.touchdown) reports where the flight crosses the commanded leg's line turned by the
pitch: the measured touchdown is carried back along its flight to where the realised leg's foot
meets the side, and the predicted one forward to where the detector's does
(:func:`_carried`; no offsets: the two are one, and nothing is carried). On vertical sides this is
the map's prediction to rounding (tests/sim_core/calibration/test_world_jumps.py).

Units: states in ``sqrt(g l0)``, heights in ``l0``, angles in radians; the world in ``l0``.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.calibration.touchdown_series import Pairs, TouchdownSeries
from sim_core.model.controls import NO_OFFSETS, ControlSchedule, LegControl, LegOffsets
from sim_core.model.errors import ParameterError
from sim_core.model.params import ModelParams
from sim_core.world.climb import climb_from_touchdown, section_orbit
from sim_core.world.geometry import LEFT, RIGHT, SideArrays, first_crossing, pack, side_x
from sim_core.world.world import World

# Columns of a Pairs row (sim_core.calibration.touchdown_series.Pairs).
XDOT, YDOT, FOOT, PSI0, ZETA0, RIGHT_LEG, PITCH = range(7)
# [sqrt(l0/g)] how far before the touchdown the flight is taken up when carried to another leg's
# line, beyond four times the vertical-wall estimate of the time between the two lines.
CARRY_MARGIN = 0.05


def world_one_jump_predictions(
    series: TouchdownSeries, models: dict[str, tuple[ModelParams, LegOffsets]], world: World
) -> dict:
    """Each touchdown of ``series`` that follows a measured one, predicted from it by each model's
    jump in ``world``; the shape of
    :func:`~sim_core.calibration.calibrate.one_jump_predictions`: ``{"index": [k...], "measured":
    (n, 3), name: (n, 3) ...}``, columns ``xdot, ydot, rise`` (NaN where a model's jump fails)."""
    pairs = Pairs.of([series])
    result = {"index": (np.flatnonzero(series.consecutive) + 1).tolist(), "measured": pairs.measured()}
    for name, (model, offsets) in models.items():
        result[name] = predict_in_world(pairs, model, offsets, world)
    return result


def predict_in_world(pairs: Pairs, model: ModelParams, offsets: LegOffsets, world: World) -> np.ndarray:
    """Shape (pairs, 3): each pair's second touchdown as the detector will report it, predicted by
    ``model`` (its legs off by ``offsets``) jumping in ``world`` from the first; NaN rows: failed."""
    sides = pack(world, model.mu)
    out = np.full((len(pairs), 3), math.nan)
    for i in range(len(pairs)):
        try:
            out[i] = _one_jump(pairs.before[i], pairs.after[i], model, offsets, world, sides)
        except ParameterError:  # a leg the offsets and pitch take out of the control domain
            continue
    return out


def _one_jump(before, after, model: ModelParams, offsets: LegOffsets, world: World, sides: SideArrays):
    side = RIGHT if before[RIGHT_LEG] > 0.5 else LEFT
    next_side = RIGHT if after[RIGHT_LEG] > 0.5 else LEFT
    leg, next_leg = _leg(before, offsets), _leg(after, offsets)
    seen, next_seen = _leg(before, NO_OFFSETS), _leg(after, NO_OFFSETS)
    real = _carried(sides, side, (before[XDOT], before[YDOT]), before[FOOT], seen, leg)
    if real is None:
        return math.nan
    state, foot = real
    schedule = ControlSchedule.of(leg, next_leg)
    climb = climb_from_touchdown(model, world, schedule, state, 1, side=side, foot_y=foot)
    if climb.failure is not None or int(climb.sides[1]) != next_side:
        return math.nan
    orbit = section_orbit(climb, schedule)
    detected = _carried(sides, next_side, orbit.states[1], foot + orbit.rises[0], next_leg, next_seen)
    if detected is None or not detected[0][0] < 0.0:
        return math.nan
    (xdot, ydot), next_foot = detected
    return xdot, ydot, next_foot - before[FOOT]


def _leg(row, offsets: LegOffsets) -> LegControl:
    """A touchdown's leg: commanded, turned by the pitch (``+`` left, ``-`` right), plus ``offsets``."""
    right = bool(row[RIGHT_LEG] > 0.5)
    pitch = -row[PITCH] if right else row[PITCH]
    return offsets.applied(LegControl(float(row[PSI0] + pitch), float(row[ZETA0])), right_leg=right)


def _carried(sides: SideArrays, side: int, state, foot: float, leg: LegControl, to: LegControl):
    """A touchdown on ``side`` met by ``leg`` (section state ``state`` flipped to that side, foot at
    ``foot`` [l0] on it) carried along its flight to where ``to``'s foot meets the side: its
    section state and foot height there, or None if the flight never brings it there."""
    xdot, ydot = float(state[0]), float(state[1])
    if to == leg:
        return (xdot, ydot), float(foot)
    mirror = 1.0 if side == LEFT else -1.0  # the side's stance frame: the side at negative x
    body_x = mirror * side_x(sides, side, foot) + leg.zeta0 * math.cos(leg.psi0)
    body_y = foot + leg.zeta0 * math.sin(leg.psi0)
    reach_x, reach_y = to.zeta0 * math.cos(to.psi0), to.zeta0 * math.sin(to.psi0)
    back = CARRY_MARGIN + 4.0 * abs(leg.zeta0 * math.cos(leg.psi0) - reach_x) / max(abs(xdot), 1e-9)
    # The foot of ``to`` on the flight, from ``back`` before this touchdown: its first crossing of the side.
    start_x = body_x - xdot * back - reach_x
    start_y = body_y - ydot * back - 0.5 * back * back - reach_y
    t, _segment = first_crossing(sides, side, mirror, start_x, start_y, xdot, ydot + back)
    if not math.isfinite(t):
        return None
    t -= back
    return (xdot, ydot - t), body_y + ydot * t - 0.5 * t * t - reach_y
