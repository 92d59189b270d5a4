"""The centre-line step of a world: on parallel walls the mid-chute map's velocities; in a world
the scipy twin's jump, entered and left at the centre line by a search of its own."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from sim_core.model.controls import LegControl
from sim_core.model.failures import FLOOR, OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noisy_map import middle_step
from sim_core.world.centre import centre_step
from sim_core.world.geometry import pack
from sim_core.world.named import named_world
from sim_core.world.reference import reference_world_jump
from sim_core.world.world import parallel

NO_RECORD = np.empty((0, STATE_SIZE))


def test_on_parallel_walls_the_velocities_are_the_mid_chute_maps(paper):
    rng = np.random.default_rng(8)
    sides, record = pack(parallel(paper.d_hat), paper.mu), paper.record()
    compared = 0
    for _ in range(300):
        speed, ydot, y = rng.uniform(0.3, 2.5), rng.uniform(-2.0, 3.0), rng.uniform(3.0, 6.0)
        psi0, zeta0 = math.radians(rng.uniform(15, 50)), rng.uniform(0.75, 0.97)
        toward = rng.choice([-1.0, 1.0])
        ours = centre_step(y, toward * speed, ydot, psi0, zeta0, record, sides, NO_RECORD)
        theirs = middle_step(speed, ydot, 0.0, psi0, zeta0, 0.0, 0.0, 0.0, 0.0, record, NO_RECORD)
        if ours[0] == FLOOR:  # the map has no floor
            continue
        assert ours[0] == theirs[0]
        if ours[0] == OK:
            compared += 1
            assert -toward * ours[2] == pytest.approx(theirs[1], abs=1e-10)
            assert ours[3] == pytest.approx(theirs[2], abs=1e-10)
    assert compared > 100


def test_in_a_world_it_is_the_scipy_twins_jump_between_two_crossings(paper):
    world = named_world("narrowing", paper.d_hat)
    sides, record = pack(world, paper.mu), paper.record()
    rng = np.random.default_rng(2)
    compared = 0
    for _ in range(40):
        y, speed, ydot = rng.uniform(1.0, 6.0), rng.uniform(0.6, 2.0), rng.uniform(-1.0, 2.0)
        leg = LegControl.from_degrees(rng.uniform(20, 40), rng.uniform(0.8, 0.95))
        toward = rng.choice([-1.0, 1.0])
        side = 0 if toward < 0 else 1
        ours = centre_step(y, toward * speed, ydot, leg.psi0, leg.zeta0, record, sides, NO_RECORD)
        # the touchdown: the coming foot's x meets its side's, found by a search along the flight
        reach = toward * leg.zeta0 * math.cos(leg.psi0)  # the foot is a leg ahead of the body

        def gap(t, y=y, speed=speed, ydot=ydot, leg=leg, reach=reach, side=side, toward=toward):
            foot_y = y + ydot * t - 0.5 * t * t - leg.zeta0 * math.sin(leg.psi0)
            wall = world.side(("left", "right")[side]).x_at(foot_y)
            return toward * (wall - (toward * speed * t + reach))

        times = np.arange(0.0, 10.0, 1e-3)
        signs = np.array([gap(t) for t in times[:4000]])
        if not (signs <= 0).any():
            continue
        first = int(np.argmax(signs <= 0))
        t = brentq(gap, times[first - 1], times[first], xtol=1e-14)
        touchdown = (toward * speed * t, y + ydot * t - 0.5 * t * t, toward * speed, ydot - t)
        status, landing, _ = reference_world_jump(paper, world, touchdown, side, leg, leg)
        if status != OK or ours[0] != OK:
            continue
        # back along the flight that ended at the landing to its crossing of x = 0
        back = -landing[0] / landing[2]
        crossing = (landing[1] + landing[3] * back - 0.5 * back * back, landing[2], landing[3] - back)
        assert np.asarray(ours[1:]) == pytest.approx(crossing, abs=1e-7)
        compared += 1
    assert compared >= 10
