"""A plan's failure chance and MFPT by splitting (sim_core/planning/plan_splitting.py): its first
attempts are the foothold study's trials of the same seeds, it agrees with Monte-Carlo where
Monte-Carlo can tell, and the ends of the scale — no noise, every attempt failing — come out exact."""

import pytest

from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.validation import ParameterError
from sim_core.planning.attempts import Attempts
from sim_core.planning.follow import follow_plan
from sim_core.planning.launch import start_velocity
from sim_core.planning.plan_splitting import PlanSplitting, plan_mfpt, plan_monte_carlo
from sim_core.planning.planner import plan_climb
from sim_core.world.random_world import random_world

GOAL = 5.0  # [l0]


@pytest.fixture(scope="module")
def climb(paper):
    world = random_world(4)
    plan = plan_climb(paper, world, GOAL, start_velocity(paper))
    assert plan.reaches_goal
    return world, plan


@pytest.mark.parametrize("replans", [0, 3])
def test_an_attempt_is_the_foothold_studys_trial_of_its_seed(paper, climb, replans):
    world, plan = climb
    noise = NoiseModel(velocity=0.03)
    follower = Attempts(paper, world, plan, GOAL, noise, max_replans=replans)
    for seed in range(12):
        attempt = follower.start(seed)
        trial = follow_plan(paper, world, plan, GOAL, noise, seed, max_replans=replans)
        assert attempt.failed == (not trial.reached)
        assert attempt.jumps == trial.jumps
        assert attempt.states[-1][3] == trial.replans


def test_it_agrees_with_monte_carlo_where_monte_carlo_can_tell(paper, climb):
    """Noise not used elsewhere (every sigma changed) and no replans, where a climb fails often
    enough for 1,500 attempts to tell: splitting's chance within Monte-Carlo's exact 95% interval, and the
    Monte-Carlo chance within splitting's (both widened by a tenth, for the two estimates' own
    spread)."""
    world, plan = climb
    noise = NoiseModel(psi0_deg=0.2, zeta0=0.0008, velocity=0.004, pitch_drift_deg=0.1)
    options = PlanSplitting(replicas=40, runs=16, seed=11, max_replans=0)
    split = plan_mfpt(paper, world, plan, GOAL, noise, options)
    check = plan_monte_carlo(paper, world, plan, GOAL, noise, options, 1500, 10**6)
    assert 0.005 < check.failure_chance < 0.5, "a setting where Monte-Carlo can tell"
    low, high = check.failure_chance_ci95
    assert 0.9 * low <= split.failure_chance <= 1.1 * high, (split.failure_chance, check.failure_chance_ci95)
    low, high = split.failure_chance_ci95
    assert 0.9 * low <= check.failure_chance <= 1.1 * high, (check.failure_chance, split.failure_chance_ci95)
    assert split.mfpt_jumps == pytest.approx(split.mean_attempt_jumps / split.failure_chance)
    assert abs(split.mean_attempt_jumps - check.mean_attempt_jumps) < 0.5


def test_without_noise_no_attempt_fails_and_its_mfpt_is_unbounded(paper, climb):
    world, plan = climb
    result = plan_mfpt(paper, world, plan, GOAL, NO_NOISE, PlanSplitting(replicas=5, runs=2))
    assert result.failure_chance == 0.0 and result.mfpt_jumps is None and result.mfpt_ci95 is None
    assert result.mean_attempt_jumps == len(plan.steps) - 1
    assert result.to_dict()["mfpt_jumps"] is None


def test_where_every_attempt_fails_the_chance_is_one(paper, climb):
    world, plan = climb
    wild = NoiseModel(psi0_deg=15.0, velocity=0.9)
    result = plan_mfpt(paper, world, plan, GOAL, wild, PlanSplitting(replicas=6, runs=2, max_replans=0))
    assert result.failure_chance == 1.0 and result.run_levels == (0, 0)
    assert result.mfpt_jumps == pytest.approx(result.mean_attempt_jumps)


@pytest.mark.parametrize(
    ("change", "field"),
    [({"replicas": 1}, "replicas"), ({"runs": 1}, "runs"), ({"max_replans": -1}, "max_replans"),
     ({"cap": 0}, "cap"), ({"seed": -1}, "seed")],
)  # fmt: skip
def test_its_options_are_checked_naming_the_field(change, field):
    with pytest.raises(ParameterError) as caught:
        PlanSplitting(**change)
    assert caught.value.field == field
