"""The climb: jump after jump between the walls, as the 3D view and the virtual robot run it.

One sequencer for every real-time climb (docs/model.md §2, §4, §5): jump ``k`` stands on
:func:`sim_core.model.walls.wall_of` ``(k)`` with that wall's leg; the leg reaching for the next wall is
read at lift-off (the robot positions it during the stance), so a jump runs in two parts —
:func:`stance`, which does not depend on the next leg, then :func:`jump` with the next leg from
:func:`read_next_leg` — or is planned whole and planned again at lift-off. Noise, when a
:class:`sim_core.model.noise_rules.NoiseSampler` is given, follows :mod:`sim_core.model.noise`'s rules in its
order: at lift-off a pitch step and the next leg's controls, after the jump the section state.
No threads, clocks or sockets here: callers stream the samples at their own pace.

Units and frame (SI, the tracker's): ``x`` [m] across the chute, 0 on its centre line, positive
toward the right wall; ``time`` [s] from the first touchdown. Each jump is simulated in the
flipped frame (stance on the left wall) and mirrored back here for right-wall jumps.

Heights: ``y`` [m] up from the chute's floor, :data:`~sim_core.climb.records.FLOOR` = 0, as the
tracker reports them. The first foot touches the left wall at the floor's height, so the body's
first touchdown is ``zeta0 l0 sin(psi0)`` above it (:func:`start_height`; 0.100 m at 30°, 0.90 on
the paper's robot).
The model alone would let a descending gait fall for ever: a climb also ends, with
:attr:`~sim_core.climb.records.ClimbEnd.FLOOR`, when the body reaches the floor; no sample lies
below it. (One convention for the 3D view and the virtual robot; the view used to start the body
0.15 m up.)

Calls: :func:`launch` (jump 0), then per jump :func:`stance` (optional), :func:`read_next_leg`,
:func:`jump` (or :func:`replan` at lift-off), :func:`touchdown_after`; :func:`simulate_climb`
runs that loop at once. What they take and return — the setup, touchdowns, next legs, samples,
jumps and ends — are the records of :mod:`sim_core.climb.records`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from sim_core.climb.records import FLOOR, ClimbEnd, ClimbSetup, Jump, JumpStart, NextLeg, Samples, Stance
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.failures import OK, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.params import PhysicalParams
from sim_core.model.trajectory import (
    FLIGHT,
    MAX_STANCE_NODES,
    STANCE,
    Trajectory,
    joined_columns,
    simulate_trajectory,
)
from sim_core.model.walls import Wall, wall_of
from sim_core.world.climb import start_foot
from sim_core.world.geometry import LEFT, RIGHT, pack
from sim_core.world.trajectory import jump_path


def start_height(leg: LegControl, robot: PhysicalParams, floor: float = FLOOR) -> float:
    """[m] body height at the first touchdown: the foot at the floor, the leg at ``leg``'s controls."""
    return floor + leg.zeta0 * robot.leg_length * math.sin(leg.psi0)


def foot_height(start: JumpStart, robot: PhysicalParams) -> float:
    """[m] the stance foot's height at touchdown ``start``."""
    return start.body_height - start.leg.zeta0 * robot.leg_length * math.sin(start.leg.psi0)


def launch(setup: ClimbSetup, commanded: LegControl, state, sampler: NoiseSampler | None = None) -> JumpStart:
    """Jump 0: the left leg, commanded ``commanded`` (noisy if ``sampler``), touches down from the floor.

    ``state`` is the section state ``(xdot, ydot)`` of that touchdown (nondimensional).
    """
    wall = wall_of(0)
    leg = commanded if sampler is None else sampler.controls(commanded, wall, 0.0)
    body_x, segment = math.nan, 0
    if setup.world is not None:  # the foot on the left side at the floor's height
        sides = pack(setup.world, setup.robot.to_model().mu)
        foot_x, segment = start_foot(sides, setup.floor / setup.robot.leg_length)
        body_x = (foot_x + leg.zeta0 * math.cos(leg.psi0)) * setup.robot.leg_length
    return JumpStart(
        jump=0,
        wall=wall,
        time=0.0,
        body_height=start_height(leg, setup.robot, setup.floor),
        state=(float(state[0]), float(state[1])),
        leg=leg,
        body_x=body_x,
        segment=segment,
    )


def read_next_leg(start: JumpStart, commanded: LegControl, sampler: NoiseSampler | None = None) -> NextLeg:
    """At lift-off of jump ``start``: the next wall's leg, commanded ``commanded``, with noise if ``sampler``."""
    if sampler is None:
        return NextLeg(commanded, start.pitch)
    pitch = sampler.pitch_step(start.pitch)
    return NextLeg(sampler.controls(commanded, start.wall.other, pitch), pitch)


def stance(setup: ClimbSetup, start: JumpStart) -> Stance:
    """The stance of jump ``start`` up to lift-off, or to the failure or floor that ends the climb.

    The stance does not depend on the next leg; a lift-off without flight (``no_flight``) is
    judged by :func:`jump`, once the next leg is known.
    """
    samples, failure, _ = _simulate(setup, start, start.leg)
    in_stance = samples.take(samples.phase == STANCE)
    in_stance, floor = _above_floor(in_stance, setup.floor)
    end = ClimbEnd.FLOOR if floor else (None if failure in (None, Failure.NO_FLIGHT) else failure)
    return Stance(start, in_stance, end)


def jump(setup: ClimbSetup, start: JumpStart, next_leg: NextLeg) -> Jump:
    """Jump ``start`` with ``next_leg`` flying to the other wall: samples, and how it ends."""
    samples, failure, outcome = _simulate(setup, start, next_leg.leg)
    samples, floor = _above_floor(samples, setup.floor)
    completed = failure is None and not floor
    rise = outcome.rise if completed else math.nan
    robot = setup.robot
    landing = _next_body_height(start, next_leg, rise, robot) if completed else math.nan
    if landing < setup.floor:
        completed, floor = False, True  # reached between the last sample and the touchdown
    top = completed and setup.top is not None and landing > setup.top
    completed = completed and not top  # landing above the top ends the climb there: no next touchdown
    flight = np.flatnonzero(samples.phase == FLIGHT)
    return Jump(
        start=start,
        next=next_leg,
        samples=samples,
        liftoff=int(flight[0]) if flight.size else len(samples),
        end=ClimbEnd.FLOOR if floor else (ClimbEnd.TOP if top else failure),
        rise=rise if completed else math.nan,
        duration=outcome.duration if completed else math.nan,
        arrival=outcome.arrival if completed else None,
        landing=outcome.landing if completed else None,
    )


def touchdown_after(setup: ClimbSetup, done: Jump, sampler: NoiseSampler | None = None) -> JumpStart:
    """The touchdown that ends jump ``done`` (process noise on its state if ``sampler``): the next jump's start."""
    if done.end is not None:
        raise ValueError(f"jump {done.start.jump + 1} ended the climb ({done.end.code}): there is no next touchdown")
    state = done.arrival if sampler is None else sampler.state(done.arrival)
    start = done.start
    return JumpStart(
        jump=start.jump + 1,
        wall=start.wall.other,  # wall_of(jump + 1) in a climb from launch()
        time=start.time + done.duration,
        body_height=_next_body_height(start, done.next, done.rise, setup.robot),
        state=state,
        leg=done.next.leg,
        pitch=done.next.pitch,
        **({} if done.landing is None else {"body_x": done.landing[0], "segment": done.landing[1]}),
    )


def replan(setup: ClimbSetup, planned: Jump, next_leg: NextLeg) -> Jump:
    """``planned`` with another leg in flight (the stance is the same); ``planned`` if unchanged.

    A climb that ended in the stance stays ended, except ``no_flight``: that is decided at lift-off
    and may depend on the next leg (one long enough to reach the other wall already).
    """
    ended_in_stance = planned.liftoff >= len(planned.samples) and planned.end is not Failure.NO_FLIGHT
    if next_leg == planned.next or ended_in_stance:
        return planned
    return jump(setup, planned.start, next_leg)


def simulate_climb(
    setup: ClimbSetup,
    commanded: Callable[[Wall], LegControl],
    state,
    jumps: int,
    sampler: NoiseSampler | None = None,
) -> list[Jump]:
    """Up to ``jumps`` jumps from the floor, all at once: the loop the real-time drivers run at their pace.

    Args:
        commanded: the controls each wall's leg is commanded at the moment they are read (jump 0's
            at launch, each next leg's at lift-off).
        state: section state ``(xdot, ydot)`` of the first touchdown (nondimensional).

    Returns:
        The jumps; the last one has an ``end`` when the climb ended before ``jumps``.
    """
    start = launch(setup, commanded(wall_of(0)), state, sampler)
    done: list[Jump] = []
    while len(done) < jumps:
        done.append(jump(setup, start, read_next_leg(start, commanded(start.wall.other), sampler)))
        if done[-1].end is not None:
            break
        start = touchdown_after(setup, done[-1], sampler)
    return done


def _next_body_height(start: JumpStart, next_leg: NextLeg, rise: float, robot: PhysicalParams) -> float:
    leg = next_leg.leg
    return foot_height(start, robot) + rise + leg.zeta0 * robot.leg_length * math.sin(leg.psi0)


class _Outcome(NamedTuple):
    """Where a completed jump leads: ``rise`` [m], ``duration`` [s], the ``arrival`` section state
    and, in a world, the ``landing`` (body x [m], segment); NaNs after a failure."""

    rise: float
    duration: float
    arrival: tuple[float, float]
    landing: tuple[float, int] | None


def _simulate(setup: ClimbSetup, start: JumpStart, next_leg: LegControl):
    """One jump, sampled: ``(samples, failure, outcome)``, the samples in SI wall coordinates."""
    if setup.world is not None:
        return _simulate_in_world(setup, start, next_leg)
    robot = setup.robot
    path = simulate_trajectory(
        robot.to_model(),
        ControlSchedule.of(start.leg, next_leg),
        start.state,
        1,
        sample_rate=setup.sample_rate,
        start_height=start.body_height / robot.leg_length,
    )
    si = path.to_si(robot)
    arrival = (float(path.section_states[-1, 0]), float(path.section_states[-1, 1]))
    completed = path.failure is None
    outcome = _Outcome(float(si.rises[0]) if completed else math.nan,
                       float(si.touchdown_times[-1]) if completed else math.nan, arrival, None)  # fmt: skip
    return _samples(si, start), path.failure, outcome


def _simulate_in_world(setup: ClimbSetup, start: JumpStart, next_leg: LegControl):
    """:func:`_simulate` in ``setup.world`` (docs/model.md §8): the jump from the body at ``start``."""
    robot = setup.robot
    model, scales = robot.to_model(), robot.scales
    side = LEFT if start.wall is Wall.LEFT else RIGHT
    mirror = -float(start.wall)
    touchdown = (start.body_x / scales.length, start.body_height / scales.length,
                 mirror * start.state[0], start.state[1])  # fmt: skip
    record = np.empty((MAX_STANCE_NODES, STATE_SIZE))
    pieces, status, landing, next_side, segment, duration = jump_path(
        model.record(), pack(setup.world, model.mu), touchdown, side, start.segment, start.leg, next_leg,
        0.0, setup.sample_rate, start.jump, record,
    )  # fmt: skip
    path = Trajectory(**joined_columns(pieces), touchdown_times=np.zeros(1), section_states=np.zeros((1, 2)),
                      rises=np.zeros(0), failure=None, failed_jump=None)  # fmt: skip
    if status != OK:
        return _samples(path.to_si(robot), start), Failure(status), _Outcome(math.nan, math.nan, (math.nan,) * 2, None)
    next_mirror = 1.0 if next_side == LEFT else -1.0
    foot = start.body_height - start.leg.zeta0 * scales.length * math.sin(start.leg.psi0)
    next_foot = (landing[1] - next_leg.zeta0 * math.sin(next_leg.psi0)) * scales.length
    outcome = _Outcome(next_foot - foot, duration * scales.time, (next_mirror * landing[2], float(landing[3])),
                       (float(landing[0]) * scales.length, int(segment)))  # fmt: skip
    return _samples(path.to_si(robot), start), None, outcome


def _samples(si: Trajectory, start: JumpStart) -> Samples:
    """A sampled jump in SI from the jump's start time on; a map's path is mirrored onto its wall
    (the simulator puts the stance on the left wall, x < 0), a world's is in wall coordinates."""
    mirror = -float(start.wall) if math.isnan(start.body_x) else 1.0
    return Samples(
        time=start.time + si.time,
        x=mirror * si.x,
        y=si.y,
        foot_x=mirror * si.foot_x,
        foot_y=si.foot_y,
        zeta=si.zeta,
        phase=si.phase.astype(int),
    )


def _above_floor(samples: Samples, floor: float) -> tuple[Samples, bool]:
    """The samples before the body first goes below ``floor``, ending on it; and whether it did."""
    below = np.flatnonzero(samples.y < floor)
    if below.size == 0:
        return samples, False
    i = int(below[0])
    if i == 0:
        kept = samples.take(slice(0, 1))
        return replace(kept, y=np.array([floor])), True
    # The last sample is where the body meets the floor, between samples i - 1 and i.
    w = (samples.y[i - 1] - floor) / (samples.y[i - 1] - samples.y[i])
    columns = {}
    for name in ("time", "x", "foot_x", "foot_y", "zeta"):
        before, after = getattr(samples, name)[i - 1 : i + 1]
        columns[name] = np.append(getattr(samples, name)[:i], before + w * (after - before))
    return Samples(
        **columns, y=np.append(samples.y[:i], floor), phase=np.append(samples.phase[:i], samples.phase[i - 1])
    ), True
