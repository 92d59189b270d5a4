"""The world's jump kernel: on parallel walls the Poincaré map's numbers (docs/model.md §8: to
1e-10), in other worlds the scipy twin's (sim_core/world/reference.py), and the failures a world
adds — a foothold's own friction cone, no touchdown, a chute too narrow for the legs."""

import math

import numpy as np
import pytest

from sim_core import ControlSchedule, LegControl, iterate_map
from sim_core.model.failures import INVALID_STATE, NO_FLIGHT, NO_TOUCHDOWN, OK, SLIP, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.stride import jump
from sim_core.world.climb import climb_world
from sim_core.world.geometry import FLIGHT_TIME_CAP, pack
from sim_core.world.reference import reference_world_jump
from sim_core.world.stride import world_jump
from sim_core.world.world import Side, World, parallel

NO_RECORD = np.empty((0, STATE_SIZE))
SAME = 1e-10  # docs/model.md §8: on parallel walls every number unchanged to 1e-10


def _legs(rng):
    return (LegControl.from_degrees(rng.uniform(10, 60), rng.uniform(0.6, 0.97)) for _ in range(2))


def _touchdown_on(world, side, leg, foot_y):
    """The body's wall coordinates with ``leg``'s foot on ``side`` at ``foot_y``."""
    mirror = 1.0 if side == 0 else -1.0
    foot_x = world.side(("left", "right")[side]).x_at(foot_y)
    return foot_x + mirror * leg.zeta0 * math.cos(leg.psi0), foot_y + leg.zeta0 * math.sin(leg.psi0)


def test_on_parallel_walls_each_jump_is_the_maps_from_either_side(paper):
    rng = np.random.default_rng(41)
    world = parallel(paper.d_hat)
    sides, record = pack(world, paper.mu), paper.record()
    statuses = set()
    for _ in range(400):
        leg, following = _legs(rng)
        xdot, ydot, foot_y = -rng.uniform(0.2, 2.5), rng.uniform(-1.5, 2.5), rng.uniform(-3, 3)
        side = int(rng.integers(2))
        mirror = 1.0 if side == 0 else -1.0
        x, y = _touchdown_on(world, side, leg, foot_y)
        ours = world_jump(x, y, mirror * xdot, ydot, side, 0, leg.psi0, leg.zeta0, following.psi0, following.zeta0,
                          record, sides, NO_RECORD)  # fmt: skip
        theirs = jump(xdot, ydot, leg.psi0, leg.zeta0, following.psi0, following.zeta0, record, NO_RECORD)
        if theirs[0] == OK and theirs[5] > FLIGHT_TIME_CAP:  # the map has no flight cap; a world does
            assert ours[0] == NO_TOUCHDOWN
            continue
        assert ours[0] == theirs[0]
        statuses.add(ours[0])
        if ours[0] == OK:
            next_foot_y = ours[2] - following.zeta0 * math.sin(following.psi0)
            assert ours[5] == 1 - side
            assert -mirror * ours[3] == pytest.approx(theirs[1], abs=SAME)  # the map's state is flipped
            assert ours[4] == pytest.approx(theirs[2], abs=SAME)
            assert next_foot_y - foot_y == pytest.approx(theirs[3], abs=SAME)
            reach = paper.d_hat / 2 - following.zeta0 * math.cos(following.psi0)
            assert ours[1] == pytest.approx(mirror * reach, abs=SAME), "the body a leg's reach off the other wall"
            assert ours[7] == theirs[4] and ours[8] == pytest.approx(theirs[5], abs=SAME)
    assert {OK, SLIP, NO_FLIGHT} <= statuses, "the draws reach the map's failures too"


@pytest.mark.parametrize("controls", [[(30, 0.9)], [(30, 0.87), (30, 0.9)], [(30, 0.9), (35, 0.9)]])
def test_on_parallel_walls_a_climb_is_the_maps_orbit(paper, controls):
    schedule = ControlSchedule.from_degrees(controls)
    for state in ((-1.0, 0.5), (-1.3, 0.9), (-0.8, 0.2)):
        climb = climb_world(paper, parallel(paper.d_hat), schedule, state, 60)
        orbit = iterate_map(paper, schedule, state, 60)
        if climb.failure is Failure.NO_TOUCHDOWN:  # a fall longer than the cap: the map has none
            last = climb.failed_jump - 1
            legs = [schedule[k] for k in (last, last + 1)]
            theirs = jump(*orbit.states[last], legs[0].psi0, legs[0].zeta0, legs[1].psi0, legs[1].zeta0,
                          paper.record(), NO_RECORD)  # fmt: skip
            assert theirs[0] == OK and theirs[5] > FLIGHT_TIME_CAP
            orbit = iterate_map(paper, schedule, state, last)
        else:
            assert (climb.failure, climb.failed_jump) == (orbit.failure, orbit.failed_jump)
        climb_states = climb.states[: len(orbit.states)]
        mirror = np.where(climb.sides[: len(climb_states)] == 0, 1.0, -1.0)
        assert np.abs(mirror * climb_states[:, 2] - orbit.states[:, 0]).max() < SAME
        assert np.abs(climb_states[:, 3] - orbit.states[:, 1]).max() < SAME
        legs = schedule.as_array()[np.arange(len(climb_states)) % len(schedule)]
        feet = climb_states[:, 1] - legs[:, 1] * np.sin(legs[:, 0])
        assert feet[0] == 0.0 and np.allclose(np.diff(feet), orbit.rises, rtol=0.0, atol=SAME)
        assert climb.sides.tolist() == [k % 2 for k in range(len(climb.states))]


def _wavy_world(rng, segments=24):
    def side(sign):
        heights = np.sort(rng.uniform(-2.0, 10.0, segments + 1))
        x = sign * (1.21 + 0.25 * np.sin(1.7 * heights + rng.uniform(0, 6)))
        return Side(np.c_[x, heights], rng.choice([np.nan, 0.3, 0.8, 3.0, np.inf], segments))

    return World(side(-1.0), side(1.0))


@pytest.mark.parametrize("seed", range(3))
def test_in_a_world_each_jump_is_the_scipy_twins(paper, seed):
    rng = np.random.default_rng(seed)
    world = _wavy_world(rng)
    sides, record = pack(world, paper.mu), paper.record()
    outcomes, compared = {}, 0
    for _ in range(60):
        leg, following = _legs(rng)
        side, foot_y = int(rng.integers(2)), rng.uniform(0.0, 6.0)
        mirror = 1.0 if side == 0 else -1.0
        x, y = _touchdown_on(world, side, leg, foot_y)
        xdot, ydot = -mirror * rng.uniform(0.4, 2.2), rng.uniform(-1.0, 2.0)
        segment = int(np.searchsorted(world.side(("left", "right")[side]).points[:, 1], foot_y, side="right")) - 1
        ours = world_jump(x, y, xdot, ydot, side, segment, leg.psi0, leg.zeta0, following.psi0, following.zeta0,
                          record, sides, NO_RECORD)  # fmt: skip
        status, touchdown, next_side = reference_world_jump(paper, world, (x, y, xdot, ydot), side, leg, following)
        assert ours[0] == status
        outcomes[status] = outcomes.get(status, 0) + 1
        if status == OK:
            compared += 1
            assert ours[5] == next_side
            # a long flight magnifies the stance's last digits: compare relative to the flight
            assert np.asarray(ours[1:5]) == pytest.approx(touchdown, rel=1e-7, abs=1e-8 * (1 + ours[8] ** 2))
    assert compared >= 15 and len(outcomes) >= 3, outcomes


def test_a_footholds_cone_is_about_its_normal(paper):
    """A touchdown at psi0 = 30° on a foothold facing 45° upward with mu = 0.3 (cone ±16.7°) holds;
    on a vertical wall with the same grip it slips at once."""
    record = paper.record()
    leg = LegControl.from_degrees(30, 0.9)
    ledge = World(Side(np.array([[-1.2, -1.0], [-2.2, 0.0], [-2.2, 1.0]]), np.array([0.3, 0.3])),
                  Side(np.array([[1.2, -1.0], [1.2, 4.0]]), np.array([np.nan])))  # fmt: skip
    x, y = _touchdown_on(ledge, 0, leg, -0.5)
    legs = (leg.psi0, leg.zeta0, leg.psi0, leg.zeta0)
    held = world_jump(x, y, -1.0, 0.5, 0, 0, *legs, record, pack(ledge, paper.mu), NO_RECORD)
    wall = World(Side(np.array([[-1.2, -1.0], [-1.2, 1.0]]), np.array([0.3])), ledge.right)
    x, y = _touchdown_on(wall, 0, leg, -0.5)
    slipped = world_jump(x, y, -1.0, 0.5, 0, 0, *legs, record, pack(wall, paper.mu), NO_RECORD)
    assert held[0] != SLIP and slipped[0] == SLIP and slipped[7] == 0.0


def test_no_grip_slips_at_once_and_a_wall_too_far_is_no_touchdown(paper):
    leg = LegControl.from_degrees(30, 0.9)
    greasy = World(Side(np.array([[-1.2, -5.0], [-1.2, 5.0]]), np.array([0.0])), parallel(2.42).right)
    assert climb_world(paper, greasy, ControlSchedule.of(leg), (-1.0, 0.5), 5).failure.code == "slip"
    far = World(parallel(2.42).left, Side(np.array([[40.0, 0.0], [40.0, 1.0]]), np.array([np.nan])))
    run = climb_world(paper, far, ControlSchedule.of(leg), (-1.0, 0.5), 5)
    assert (run.failure.code, run.failed_jump) == ("no_touchdown", 1) and NO_TOUCHDOWN == 7
    narrow = parallel(1.2)
    assert climb_world(paper, narrow, ControlSchedule.of(leg), (-1.0, 0.5), 5).failure.code == "no_flight"


def test_a_state_flying_away_from_its_side_is_invalid(paper):
    leg = LegControl.from_degrees(30, 0.9)
    sides = pack(parallel(paper.d_hat), paper.mu)
    legs = (leg.psi0, leg.zeta0, leg.psi0, leg.zeta0)
    away = world_jump(1.0, 0.5, -1.0, 0.5, 1, 0, *legs, paper.record(), sides, NO_RECORD)
    assert away[0] == INVALID_STATE
