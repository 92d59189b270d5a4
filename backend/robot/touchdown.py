"""Touchdowns from tracker poses: the robot's Poincaré section states and height gains.

The PC knows each touchdown's controls, so it knows where the body is when a foot meets the
wall: ``zeta0 l0 cos psi`` from it, the leg's angle ``psi`` being the commanded ``psi0`` turned by the
body's pitch when the tracker gives one (``+pitch`` on the left wall, ``-pitch`` on the right, the
convention of docs/model.md §5.1): the leg is fixed to the body. A touchdown is the tracked body
crossing that line on its way to the wall. Between the chute's centre line and that crossing the body is in flight, so
those poses follow ``x = a + b t`` and ``y = c + e t - g t^2 / 2`` exactly: a least-squares fit
through them gives the crossing time and the velocity at touchdown, averaging tracker noise and
bridging dropped frames. States come out as the simulator's — nondimensional, flipped so every
touchdown is on the left wall — so robot and model compare jump by jump.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sim_core.model.controls import LegControl
from sim_core.model.params import PhysicalParams
from sim_core.model.walls import Wall

SideAt = Callable[[Wall, float], float]  # a world's side: its x [m] at a height [m]
MIN_FIT_POSES = 4
PITCH_LOOKBACK = 10  # poses looked back through for the newest pitch the markers gave


@dataclass(frozen=True)
class Touchdown:
    """One detected touchdown (SI time and heights; nondimensional section state)."""

    index: int  # 0-based touchdown number
    time: float  # [s]
    wall: Wall  # the wall the foot met
    state: tuple[float, float]  # (xdot, ydot) [sqrt(g l0)], flipped to the left wall
    body_height: float  # [m]
    foot_height: float  # [m]
    poses_fitted: int
    body_x: float | None = None  # [m] where the body was at touchdown (x across the chute); None: stored before

    def to_dict(self) -> dict:
        """As JSON stores it (the wall as its sign, the state as a list)."""
        return {**vars(self), "wall": int(self.wall), "state": list(self.state)}

    @classmethod
    def from_dict(cls, stored: dict) -> Touchdown:
        return cls(**{**stored, "wall": Wall(stored["wall"]), "state": tuple(stored["state"])})


def detect_touchdowns(
    time: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    robot: PhysicalParams,
    leg_for: Callable[[int], LegControl],
    pitch: np.ndarray | None = None,
    side_at: SideAt | None = None,
) -> list[Touchdown]:
    """Touchdowns in a pose stream (SI, wall coordinates; ``leg_for(k)`` is touchdown k's controls;
    ``pitch`` [rad] per pose, NaN where the markers gave none, or None; ``side_at(wall, y)`` the x
    [m] of the chute's side at height ``y`` [m] in a world, None between parallel walls).

    A crossing whose flight could not be fitted (fewer than ``MIN_FIT_POSES`` flight poses) is
    skipped; the stream may start and end anywhere.
    """
    return scan_touchdowns(time, x, y, robot, leg_for, pitch, side_at=side_at).touchdowns


@dataclass(frozen=True)
class Scan:
    """What :func:`scan_touchdowns` found, and where a scan of the same stream, grown since, goes on."""

    touchdowns: list[Touchdown]
    resume: int  # the next scan's ``start``: the pose where an unfinished flight began, else the end


def scan_touchdowns(
    time: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    robot: PhysicalParams,
    leg_for: Callable[[int], LegControl],
    pitch: np.ndarray | None = None,
    *,
    start: int = 1,
    first_index: int = 0,
    side_at: SideAt | None = None,
) -> Scan:
    """:func:`detect_touchdowns` from pose ``start`` on (the poses before it only give the pitch
    looked back to and the centre-line crossing at ``start``), numbering touchdowns from
    ``first_index``. A live run scans only what came since its last scan's ``resume``, so each new
    pose costs the same however long the run has gone; the touchdowns are those one scan of the
    whole stream finds."""
    scales = robot.scales
    half = 0.5 * robot.wall_distance
    touchdowns: list[Touchdown] = []
    flight_start = None  # index where the body crossed the centre line heading for a wall
    for i in range(max(start, 1), len(time)):
        if x[i - 1] * x[i] <= 0.0 and x[i] != x[i - 1]:
            flight_start = i
            continue
        if flight_start is None:
            continue
        wall = Wall.RIGHT if x[i] > 0 else Wall.LEFT
        number = first_index + len(touchdowns)
        leg = leg_for(number)
        psi = leg.psi0 - wall * pitch_before(pitch, i)  # the leg turned with the body
        reach_x, reach_y = leg.zeta0 * robot.leg_length * math.cos(psi), leg.zeta0 * robot.leg_length * math.sin(psi)
        side = wall * half if side_at is None else side_at(wall, y[i] - reach_y)  # where the foot meets it
        line = side - wall * reach_x
        if wall * x[i] < wall * line:
            continue
        fit = slice(flight_start, i)  # flight poses before the line
        flight_start = None
        if fit.stop - fit.start < MIN_FIT_POSES:
            continue
        t, xs, ys = time[fit], x[fit], y[fit]
        t0 = t[0]
        b, a = np.polyfit(t - t0, xs, 1)
        e, c = np.polyfit(t - t0, ys + 0.5 * robot.gravity * (t - t0) ** 2, 1)
        crossing = (line - a) / b
        vx, vy = b, e - robot.gravity * crossing
        body = c + e * crossing - 0.5 * robot.gravity * crossing**2
        state = (-wall * vx / scales.velocity, vy / scales.velocity)  # the flip: toward the wall is -x
        touchdowns.append(
            Touchdown(
                index=number,
                time=t0 + crossing,
                wall=wall,
                state=state,
                body_height=body,
                foot_height=body - reach_y,
                poses_fitted=fit.stop - fit.start,
                body_x=line,
            )
        )
    return Scan(touchdowns, len(time) if flight_start is None else flight_start)


def pitch_before(pitch: np.ndarray | None, i: int, missing: float = 0.0) -> float:
    """The body's pitch at pose ``i``: its own, else the newest finite one of the
    :data:`PITCH_LOOKBACK` poses before it, else ``missing`` (also without a pitch stream)."""
    if pitch is None:
        return missing
    for j in range(i, max(i - PITCH_LOOKBACK, -1), -1):
        if math.isfinite(pitch[j]):
            return float(pitch[j])
    return missing


def height_gains(touchdowns: list[Touchdown], robot: PhysicalParams) -> np.ndarray:
    """Per-jump height gain between consecutive touchdowns [l0], as the simulator's ``rises``."""
    feet = np.array([td.foot_height for td in touchdowns])
    return np.diff(feet) / robot.leg_length
