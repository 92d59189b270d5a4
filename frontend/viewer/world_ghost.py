"""The model's jump in a stored world from a live touchdown: live mode's ghost in a world
(docs/model.md §8; :mod:`frontend.viewer.modes.live`). No viser here.

The jump starts where :func:`sim_core.world.climb.climb_from_touchdown` starts a climb from a tracked
touchdown (:func:`sim_core.world.climb.first_touchdown`): the foot on the side the touchdown met, at
the foot's height, the body at the foot plus the leg the touchdown was made with, arriving with the
touchdown's section state. From there it is the climb sequencer's jump in the world
(:func:`sim_core.climb.sequencer.jump` with ``ClimbSetup.world``: each jump sampled by
:func:`sim_core.world.trajectory.jump_path` on the kernel that climbs worlds), so its stance stands on
the world's side and its flight ends where the world's climb puts the next touchdown. The samples
stop short of that touchdown (they are taken at the sample rate's clock), so one more is added at it:
the ghost ends on the next touchdown itself. A jump that fails (a slip, no foothold, the chute's
floor) is drawn up to the failure, as :func:`frontend.viewer.simulated_climb.model_jump`'s between
the walls; a touchdown that slips at once is drawn as its one pose.

Units: SI wall coordinates (the tracker's), the world in ``l0`` of the robot the jump is made by.
"""

from __future__ import annotations

import math

import numpy as np

from frontend.viewer.simulated_climb import JumpPlan
from sim_core import LegControl, PhysicalParams
from sim_core.climb import sequencer as climb
from sim_core.climb.records import ClimbSetup, Jump, JumpStart, NextLeg, Samples
from sim_core.model.controls import ControlSchedule
from sim_core.model.trajectory import FLIGHT, STANCE
from sim_core.model.walls import Wall
from sim_core.world.climb import first_touchdown
from sim_core.world.geometry import LEFT, RIGHT
from sim_core.world.world import Side, World


def world_jump(
    robot: PhysicalParams,
    world: World,
    state: tuple[float, float],
    leg: LegControl,
    next_leg: LegControl,
    *,
    wall: Wall,
    start_time: float,
    foot_height: float,
    jump_index: int = 0,
) -> JumpPlan:
    """One jump of ``robot``'s model in ``world`` (``l0`` of ``robot``) from a touchdown on ``wall``.

    Args:
        state: ``(xdot, ydot)`` at touchdown, nondimensional and flipped to the wall's side
            (``xdot < 0``), as a detected touchdown gives it.
        leg: the leg the touchdown was made with; next_leg: the one flying to the other side.
        start_time: [s] the touchdown's time; foot_height: [m] its foot's height on the side.

    Raises:
        ParameterError: a state or leg outside the model's domain.
    """
    model, l0 = robot.to_model(), robot.leg_length
    side = LEFT if wall == Wall.LEFT else RIGHT
    body, segment = first_touchdown(model, world, ControlSchedule.of(leg), state, foot_height / l0, side=side)
    start = JumpStart(jump_index, Wall(wall), start_time, float(body[1]) * l0, (float(state[0]), float(state[1])),
                      leg, body_x=float(body[0]) * l0, segment=segment)  # fmt: skip
    setup = ClimbSetup(robot, world=world)
    done = climb.jump(setup, start, NextLeg(next_leg))
    return JumpPlan.of(done, robot, _drawn(setup, done))


def in_leg_lengths(world: World, drawn_at: float, robot: PhysicalParams) -> World:
    """``world`` (``l0`` of a leg ``drawn_at`` [m] long, as the view draws it) in ``robot``'s ``l0``:
    the same sides in metres for a model of another leg length."""
    if robot.leg_length == drawn_at:
        return world
    scale = drawn_at / robot.leg_length
    return World(*(Side(side.points * scale, side.mu) for side in (world.left, world.right)), world.name)


def _drawn(setup: ClimbSetup, done: Jump) -> Samples:
    """``done``'s samples to draw: with the next touchdown added after a completed jump, and the
    touchdown's own pose when the jump failed before its first sample (a slip at once)."""
    start, l0 = done.start, setup.robot.leg_length
    if done.end is None:
        after = climb.touchdown_after(setup, done)
        return _joined(done.samples, _pose(after.time, after.body_x, after.body_height, done.next.leg,
                                           start.wall.other, FLIGHT, l0))  # fmt: skip
    if len(done.samples) == 0:
        return _pose(start.time, start.body_x, start.body_height, start.leg, start.wall, STANCE, l0)
    return done.samples


def _pose(time: float, x: float, y: float, leg: LegControl, wall: Wall, phase: int, l0: float) -> Samples:
    """One sample: the body at ``(x, y)`` [m], ``leg``'s foot toward ``wall``."""
    reach_x, reach_y = leg.zeta0 * l0 * math.cos(leg.psi0), leg.zeta0 * l0 * math.sin(leg.psi0)
    columns = (time, x, y, x + float(wall) * reach_x, y - reach_y, leg.zeta0 * l0)
    return Samples(*(np.array([value]) for value in columns), phase=np.array([phase]))


def _joined(samples: Samples, more: Samples) -> Samples:
    return Samples(**{name: np.concatenate([getattr(samples, name), getattr(more, name)]) for name in Samples.COLUMNS})
