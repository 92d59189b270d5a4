"""The foot-placement law: the leg angle it reads off the tracked body is the one the noise made;
the leg it chooses lands, on the model, on the aimed foothold with its margins; it follows a
plan's own legs where nothing is off."""

import math

import numpy as np
import pytest

from sim_core.control.laws.placement import PlacementSettings
from sim_core.control.placement import OFF_PLAN, PLACED, leg_on_wall, place_leg
from sim_core.model.errors import ParameterError
from sim_core.model.integrate import STATE_SIZE
from sim_core.planning.follow import plan_aims
from sim_core.planning.planner import plan_climb
from sim_core.world.geometry import pack, side_x
from sim_core.world.random_world import random_world
from sim_core.world.stride import world_jump

START = (-1.0, 0.5)
NO_RECORD = np.empty((0, STATE_SIZE))


def _body(step):
    """The body at a plan's touchdown: its foot plus the leg toward the middle."""
    inward = 1.0 if step.side == 0 else -1.0
    return (step.target[0] + inward * step.leg.zeta0 * math.cos(step.leg.psi0),
            step.target[1] + step.leg.zeta0 * math.sin(step.leg.psi0))  # fmt: skip


@pytest.mark.parametrize("seed", [3, 8, 13])
def test_the_leg_angle_read_off_the_body_is_the_one_that_put_the_foot_on_the_wall(paper, seed):
    world, rng = random_world(seed), np.random.default_rng(seed)
    sides = pack(world, paper.mu)
    for _ in range(40):
        side = int(rng.integers(2))
        foot_y = rng.uniform(0.0, world.top - 0.5)
        psi0, zeta0 = math.radians(rng.uniform(12.0, 55.0)), rng.uniform(0.8, 0.97)
        inward = 1.0 if side == 0 else -1.0
        x = side_x(sides, side, foot_y) + inward * zeta0 * math.cos(psi0)
        y = foot_y + zeta0 * math.sin(psi0)
        guess = psi0 + math.radians(rng.uniform(-1.0, 1.0))  # the angle sent, turned by the pitch
        assert leg_on_wall(sides, side, x, y, guess, zeta0) == pytest.approx(psi0, abs=1e-9)


@pytest.mark.parametrize("seed", [1, 5])
def test_the_chosen_leg_lands_on_the_aimed_foothold_with_its_margins(paper, seed):
    world, settings = random_world(seed), PlacementSettings()
    sides = pack(world, paper.mu)
    plan = plan_climb(paper, world, 5.0, START)
    aims = plan_aims(plan)
    rng = np.random.default_rng(seed)
    placed = 0
    for k, step in enumerate(plan.steps[:-1]):
        x, y = _body(step)
        xdot, ydot = step.velocity[0] + rng.normal(0, 0.01), step.velocity[1] + rng.normal(0, 0.01)  # a little off
        found, psi0, zeta0 = place_leg(paper.record(), sides, x, y, xdot, ydot, step.side, step.segment,
                                       step.leg.psi0, step.leg.zeta0, aims[k + 1], settings.array())  # fmt: skip
        if found != PLACED:
            continue
        placed += 1
        low, high = (math.radians(v) for v in settings.psi0_range_deg)
        assert low <= psi0 <= high and settings.zeta0_range[0] <= zeta0 <= settings.zeta0_range[1]
        status, _, y1, *_, side, segment, _, _, _ = world_jump(
            x, y, xdot, ydot, step.side, step.segment, step.leg.psi0, step.leg.zeta0, psi0, zeta0, paper.record(),
            sides, NO_RECORD,
        )  # fmt: skip
        assert status == 0 and (side, segment) == (1 - step.side, int(aims[k + 1, 0]))
        foot_y = y1 - zeta0 * math.sin(psi0)
        points = world.left.points if side == 0 else world.right.points
        low_end, high_end = points[segment], points[segment + 1]
        length = math.dist(low_end, high_end)
        share = (foot_y - low_end[1]) / (high_end[1] - low_end[1])
        assert min(share, 1 - share) * length >= min(settings.end_margin, 0.25 * length) - 1e-9
        beta = sides.beta[side, segment + 1]
        half = math.atan(sides.friction[side, segment + 1])
        assert half - abs(psi0 - beta) >= min(math.radians(settings.cone_margin_deg), 0.5 * half) - 1e-12
    assert placed >= len(plan.steps) - 2, "a state near the plan's is placed nearly every time"


def test_on_the_plans_own_touchdowns_the_law_sends_the_plans_own_legs(paper):
    world = random_world(4)
    sides = pack(world, paper.mu)
    plan = plan_climb(paper, world, 5.0, START)
    aims = plan_aims(plan)
    settings = PlacementSettings().array()
    for k, step in enumerate(plan.steps[:-1]):
        found, psi0, zeta0 = place_leg(paper.record(), sides, *_body(step), *step.velocity, step.side, step.segment,
                                       step.leg.psi0, step.leg.zeta0, aims[k + 1], settings)  # fmt: skip
        following = plan.steps[k + 1].leg
        assert found == PLACED and (psi0, zeta0) == pytest.approx((following.psi0, following.zeta0), abs=1e-12)


def test_an_unreachable_foothold_is_said_to_be_off_plan(paper):
    world = random_world(4)
    sides = pack(world, paper.mu)
    plan = plan_climb(paper, world, 5.0, START)
    aims = plan_aims(plan)
    step, far = plan.steps[0], aims[-1].copy()  # the last foothold of the plan, many jumps up
    found, _, _ = place_leg(paper.record(), sides, *_body(step), *step.velocity, step.side, step.segment,
                            step.leg.psi0, step.leg.zeta0, far, PlacementSettings().array())  # fmt: skip
    assert found == OFF_PLAN


def test_bad_settings_are_refused_naming_the_field():
    with pytest.raises(ParameterError, match="end_margin"):
        PlacementSettings(end_margin=-0.1)
    with pytest.raises(ParameterError, match="zeta0_range"):
        PlacementSettings(zeta0_range=(0.9, 0.8))


def test_from_a_tracked_lift_off_the_chosen_leg_lands_on_the_aimed_foothold(paper):
    from sim_core.control.placement import place_from_liftoff
    from sim_core.world.stride import world_flight

    world = random_world(9)
    sides = pack(world, paper.mu)
    plan = plan_climb(paper, world, 5.0, START)
    aims = plan_aims(plan)
    rng = np.random.default_rng(9)
    for k, step in enumerate(plan.steps[:-1]):
        x, y = _body(step)
        # the true stance, its leg a little off what was sent: the lift-off the tracker sees
        status, lift_x, lift_y, lift_xdot, lift_ydot, *_ = _lift_off(paper, sides, x, y, step, rng)
        if status != 0:
            continue
        found, psi0, zeta0 = place_from_liftoff(paper.record(), sides, step.side, lift_x, lift_y, lift_xdot, lift_ydot,
                                                aims[k + 1], PlacementSettings().array())  # fmt: skip
        if found == PLACED:
            landed = world_flight(lift_x, lift_y, lift_xdot, lift_ydot, step.side, psi0, zeta0, sides)
            assert landed[0] == 0 and landed[5] == int(aims[k + 1, 0])


def _lift_off(model, sides, x, y, step, rng):
    """The lift-off of ``step``'s stance with its leg's length drawn (the angle then the wall's)."""
    from sim_core.model.integrate import PSI, PSI_DOT, ZETA_DOT
    from sim_core.model.stride import liftoff_velocity
    from sim_core.world.stride import foothold_stance

    zeta0 = step.leg.zeta0 + rng.normal(0.0, 0.003)
    psi0 = leg_on_wall(sides, step.side, x, y, step.leg.psi0, zeta0)
    mirror = 1.0 if step.side == 0 else -1.0
    final = np.empty(STATE_SIZE)
    status, _ = foothold_stance(mirror * step.velocity[0], step.velocity[1], psi0, zeta0, model.record(), sides,
                                step.side, step.segment, final, NO_RECORD)  # fmt: skip
    vx, vy = liftoff_velocity(final[PSI], final[ZETA_DOT], final[PSI_DOT])
    lift_x = x - mirror * (zeta0 * math.cos(psi0) - math.cos(final[PSI]))
    lift_y = y - zeta0 * math.sin(psi0) + math.sin(final[PSI])
    return status, lift_x, lift_y, mirror * vx, vy
