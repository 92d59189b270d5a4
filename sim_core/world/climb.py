"""A climb in a world, validated and typed (docs/model.md §8): ``parkour climb``'s engine.

Touchdown 0 is on the left side with the foot on its polyline at height ``foot_y`` and the body
arriving with velocity ``(xdot, ydot)`` (``xdot < 0``), as ``parkour map --state`` takes it. Jump
``k`` uses schedule row ``k % m`` while the sides alternate. No noise, pitch or floor unless asked.
:func:`climb_from_touchdown` starts instead from a touchdown seen on either side (a tracked robot's
first), and :func:`section_orbit` reads a climb as the Poincaré map's :class:`~sim_core.model.poincare.Orbit`.

>>> from sim_core import ControlSchedule, get_preset
>>> from sim_core.world.world import parallel
>>> model = get_preset("paper").to_model()
>>> run = climb_world(model, parallel(model.d_hat), ControlSchedule.from_degrees([(30, 0.9)]), (-1.0, 0.5), 3)
>>> run.failure is None, run.states.shape, [int(side) for side in run.sides]
(True, (4, 4), [0, 1, 0, 1])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.model.controls import PSI0_COLUMN, ZETA0_COLUMN, ControlSchedule
from sim_core.model.errors import ParameterError
from sim_core.model.failures import FLOOR_HEIGHT, OK, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.params import ModelParams
from sim_core.model.poincare import Orbit, check_jumps, check_section_state
from sim_core.model.validation import check_range
from sim_core.model.walls import Wall, wall_of
from sim_core.world.geometry import LEFT, RIGHT, SIDE_NAMES, pack, segment_at, side_x
from sim_core.world.stride import TOUCHDOWN_SIZE, world_jump, world_orbit
from sim_core.world.world import World


@dataclass(frozen=True)
class WorldClimb:
    """The touchdowns of one climb in a world.

    Attributes:
        states: shape (k + 1, 4), the body at touchdowns 0..k: ``x, y, xdot, ydot`` in wall
            coordinates [l0, sqrt(g l0)].
        sides: shape (k + 1,), 0 left, 1 right. segments: shape (k + 1,), as docs/model.md §8.
        failure: why the climb stopped early, or None. failed_jump: its 1-based jump, or None.
    """

    states: np.ndarray
    sides: np.ndarray
    segments: np.ndarray
    failure: Failure | None
    failed_jump: int | None

    def to_dict(self) -> dict:
        """The ``parkour climb --json`` contract: every touchdown (0 included, ``jump`` 0-based)
        and the failure (``jump`` 1-based) or None."""
        touchdowns = [
            {
                "jump": jump,
                "side": SIDE_NAMES[int(self.sides[jump])],
                "segment": int(self.segments[jump]),
                "x": float(x),
                "y": float(y),
                "xdot": float(xdot),
                "ydot": float(ydot),
            }
            for jump, (x, y, xdot, ydot) in enumerate(self.states)
        ]
        failure = None if self.failure is None else {"code": self.failure.code, "jump": self.failed_jump}
        return {"touchdowns": touchdowns, "failure": failure}


def first_touchdown(
    model: ModelParams, world: World, schedule: ControlSchedule, state, foot_y: float = 0.0, *, side: int = LEFT
):
    """Touchdown 0 (docs/model.md §8): ``(row, segment)``, the body's ``x, y, xdot, ydot`` (wall
    coordinates) with the foot on ``side`` (0 left, 1 right) at ``foot_y`` [l0] under schedule row 0,
    and the foot's segment. ``state`` is the section state ``(xdot, ydot)`` flipped into the side's
    stance frame (``xdot < 0``: toward that side, as the map's and a tracked touchdown's); on the
    right side it is mirrored back (``x -> -x``) into wall coordinates."""
    velocity = check_section_state(state)
    foot_y = check_range("foot_y", foot_y)
    if side not in (LEFT, RIGHT):
        raise ParameterError("side", f"must be {LEFT} (left) or {RIGHT} (right), got {side!r}")
    foot_x, segment = start_foot(pack(world, model.mu), foot_y, side)
    mirror = 1.0 if side == LEFT else -1.0  # the side's stance frame: x -> mirror * x
    leg = schedule[0]
    body = (foot_x + mirror * leg.zeta0 * math.cos(leg.psi0), foot_y + leg.zeta0 * math.sin(leg.psi0))
    return np.array([*body, mirror * velocity[0], velocity[1]]), segment


def start_foot(sides, foot_y: float, side: int = LEFT) -> tuple[float, int]:
    """Touchdown 0's foot on ``side`` (the kernels' record ``sides``; left unless asked) at height
    ``foot_y`` [l0]: its ``x`` [l0] and its segment."""
    return float(side_x(sides, side, foot_y)), int(segment_at(sides, side, foot_y))


def climb_world(
    model: ModelParams,
    world: World,
    schedule: ControlSchedule,
    state,
    jumps: int,
    *,
    foot_y: float = 0.0,
    noise: NoiseModel | None = None,
    seed: int = 0,
    floor: bool = False,
) -> WorldClimb:
    """Climb ``jumps`` jumps in ``world`` from touchdown 0 (see the module). A failing jump ends
    the climb; the result says which and why. Asked for: ``noise`` (docs/model.md §5.1, pitch
    included, drawn in its rules' order from ``seed``) and the ``floor`` (a touchdown with the body
    below ``y = 0`` ends the climb there, code ``floor``, docs/model.md §7.2)."""
    jumps = check_jumps(jumps)
    if noise is not None:
        climb = _noisy_climb(model, world, schedule, state, jumps, foot_y, noise, seed)
    else:
        climb = climb_from_touchdown(model, world, schedule, state, jumps, side=LEFT, foot_y=foot_y)
    return _cut_at_floor(climb) if floor else climb


def climb_from_touchdown(
    model: ModelParams, world: World, schedule: ControlSchedule, state, jumps: int, *, side: int, foot_y: float
) -> WorldClimb:
    """Climb ``jumps`` jumps in ``world`` from a touchdown on either ``side`` (0 left, 1 right): the
    foot on it at height ``foot_y`` [l0] under schedule row 0, the body arriving with the section
    state ``state = (xdot, ydot)`` [sqrt(g l0)] flipped into that side's stance frame (``xdot < 0``),
    as a tracked robot's touchdown gives it (:func:`first_touchdown`). Jump ``k`` uses schedule rows
    ``k`` and ``k + 1`` (mod its length); no noise, pitch or floor. A failing jump ends the climb."""
    jumps = check_jumps(jumps)
    start, segment = first_touchdown(model, world, schedule, state, foot_y, side=side)
    states = np.empty((jumps + 1, TOUCHDOWN_SIZE))
    states[0] = start
    sides = np.zeros(jumps + 1, dtype=np.int64)
    segments = np.zeros(jumps + 1, dtype=np.int64)
    sides[0], segments[0] = side, segment
    status, completed = world_orbit(
        schedule.as_array(), 0, model.record(), pack(world, model.mu), states, sides, segments
    )
    return _ended(states, sides, segments, status, completed)


def section_orbit(climb: WorldClimb, schedule: ControlSchedule) -> Orbit:
    """``climb`` (made with ``schedule``, touchdown ``k`` under row ``k`` mod its length) as the
    Poincaré map gives its orbits (:func:`sim_core.model.poincare.iterate_map`): each touchdown's
    ``(xdot, ydot)`` [sqrt(g l0)] flipped to the left wall (a right side's ``xdot`` negated), each
    jump's rise [l0] the next foot's height minus this foot's (the feet where the scheduled legs put
    them), and the failure with its 1-based jump. On parallel walls it is the map's orbit to rounding."""
    legs = schedule.as_array()[np.arange(climb.states.shape[0]) % len(schedule)]
    feet = climb.states[:, 1] - legs[:, ZETA0_COLUMN] * np.sin(legs[:, PSI0_COLUMN])
    flip = np.where(climb.sides == LEFT, 1.0, -1.0)  # the stance frame: the right side's x mirrored
    states = np.column_stack([flip * climb.states[:, 2], climb.states[:, 3]])
    return Orbit(states=states, rises=np.diff(feet), failure=climb.failure, failed_jump=climb.failed_jump)


def _ended(states, sides, segments, status, completed) -> WorldClimb:
    if status == OK:
        return WorldClimb(states, sides, segments, None, None)
    kept = completed + 1
    return WorldClimb(states[:kept].copy(), sides[:kept].copy(), segments[:kept].copy(), Failure(status), completed + 1)


def _cut_at_floor(climb: WorldClimb) -> WorldClimb:
    """``climb`` ended at its first touchdown (after touchdown 0) with the body below the floor."""
    below = np.flatnonzero(climb.states[1:, 1] < FLOOR_HEIGHT)
    if below.size == 0:
        return climb
    k = int(below[0]) + 1  # jump k (1-based) ended below the floor: touchdowns 0 .. k - 1 stand
    return WorldClimb(climb.states[:k].copy(), climb.sides[:k].copy(), climb.segments[:k].copy(), Failure.FLOOR, k)


def _noisy_climb(model, world, schedule, state, jumps, foot_y, noise, seed) -> WorldClimb:
    """The climb with the legs, pitch and velocity drawn as docs/model.md §5.1 says, jump by jump."""
    sampler = NoiseSampler(noise, np.random.default_rng(seed))
    pitch = 0.0
    leg = sampler.controls(schedule[0], Wall.LEFT, pitch)
    start, segment = first_touchdown(model, world, ControlSchedule.of(leg), state, foot_y)
    sides_arrays, record, no_record = pack(world, model.mu), model.record(), np.empty((0, STATE_SIZE))
    states, sides, segments = [start], [LEFT], [segment]
    status = OK
    for k in range(jumps):
        next_pitch = sampler.pitch_step(pitch)
        next_leg = sampler.controls(schedule[k + 1], wall_of(k + 1), next_pitch)
        x, y, xdot, ydot = states[-1]
        status, *landing, side, segment, _, _, _ = world_jump(
            x, y, xdot, ydot, sides[-1], segments[-1], leg.psi0, leg.zeta0, next_leg.psi0, next_leg.zeta0,
            record, sides_arrays, no_record,
        )  # fmt: skip
        if status != OK:
            break
        mirror = 1.0 if side == LEFT else -1.0  # the velocity's noise in the coming stance's frame
        flipped_xdot, landing[3] = sampler.state((mirror * landing[2], landing[3]))
        landing[2] = mirror * flipped_xdot
        states.append(np.array(landing))
        sides.append(side)
        segments.append(segment)
        pitch, leg = next_pitch, next_leg
    completed = len(states) - 1
    return _ended(np.array(states), np.array(sides), np.array(segments), status, completed)
