"""A plan followed live (sim_core/planning/live.py): from each touchdown of a noiseless simulated
climb of the plan, the leg it decides is the one the simulated law sent (sim_core/planning/follow.py
via the attempts that step it), on random-foothold worlds it was not tuned to."""

import math

import numpy as np
import pytest

from sim_core import get_preset
from sim_core.control.placement import OFF_PLAN, PLACED
from sim_core.model.noise import NO_NOISE
from sim_core.planning.attempts import Attempts
from sim_core.planning.follow import PSI0, SENT_PSI0, SENT_ZETA0, SIDE, XDOT, YDOT, ZETA0, X, Y
from sim_core.planning.launch import start_velocity
from sim_core.planning.live import LivePlan
from sim_core.planning.planner import plan_climb
from sim_core.world.random_world import random_world


@pytest.mark.parametrize("seed", [3, 8, 21])
def test_the_live_law_sends_the_simulated_laws_legs(seed):
    model = get_preset("paper").to_model()
    world = random_world(seed, width=model.d_hat)
    plan = plan_climb(model, world, 3.0, start_velocity(model), seed=seed)
    assert plan.reaches_goal and len(plan.steps) >= 3
    attempt = Attempts(model, world, plan, 3.0, NO_NOISE, max_replans=0).start(seed)
    live = LivePlan.of(model, world, [step.to_dict() for step in plan.steps])
    checked = 0
    for (trial, _aims, row, _), (after, *_) in zip(attempt.states, attempt.states[1:], strict=False):
        placed = live.next_leg(row, (trial[X], trial[Y]), (trial[XDOT], trial[YDOT]), int(trial[SIDE]),
                               (trial[PSI0], trial[ZETA0]))  # fmt: skip
        assert placed.found == PLACED and placed.side == int(after[SIDE])
        assert (placed.psi0, placed.zeta0) == pytest.approx((after[SENT_PSI0], after[SENT_ZETA0]), abs=1e-9)
        side, segment, target = live.planned(row + 1)
        assert (placed.segment, placed.target) == (segment, target) and side == placed.side
        checked += 1
    assert checked >= 2


def test_past_the_plans_end_there_is_no_leg():
    model = get_preset("paper").to_model()
    world = random_world(3, width=model.d_hat)
    plan = plan_climb(model, world, 1.0, start_velocity(model))
    live = LivePlan.of(model, world, [step.to_dict() for step in plan.steps])
    last = plan.steps[-1]
    body = (last.target[0] + math.cos(last.leg.psi0) * last.leg.zeta0, last.target[1] + 0.3)
    placed = live.next_leg(len(plan.steps) - 1, body, last.velocity, last.side, (last.leg.psi0, last.leg.zeta0))
    assert placed.found == OFF_PLAN and np.isnan(placed.psi0)
