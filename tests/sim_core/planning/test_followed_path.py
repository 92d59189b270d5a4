"""The path of a followed plan: its touchdowns are follow_plan's trial's, and each sampled jump
lands where the trial's next touchdown is."""

import numpy as np
import pytest

from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.planning.follow import follow_plan
from sim_core.planning.followed_path import followed_path
from sim_core.planning.planner import plan_climb
from sim_core.world.random_world import random_world

START = (-1.0, 0.5)


@pytest.fixture(scope="module")
def planned(paper_module):
    world = random_world(2)
    return world, plan_climb(paper_module, world, 5.0, START)


@pytest.fixture(scope="module")
def paper_module():
    from sim_core import get_preset

    return get_preset("paper").to_model()


NOISY = NoiseModel(psi0_deg=1.0, zeta0=0.006, velocity=0.02, pitch_drift_deg=1.0)  # replans: 1 to 3
WILD = NoiseModel(psi0_deg=3.0, zeta0=0.02, velocity=0.08, pitch_drift_deg=3.0)  # seeds 1 and 2 fail


@pytest.mark.parametrize(("noise", "seed"), [(NOISY, 7), (NOISY, 8), (NOISY, 9), (WILD, 1), (WILD, 2)])
def test_the_path_is_follow_plans_trial_and_lands_on_its_touchdowns(paper_module, planned, noise, seed):
    world, plan = planned
    outcome = follow_plan(paper_module, world, plan, 5.0, noise, seed)
    path = followed_path(paper_module, world, plan, 5.0, noise, seed)
    assert (path.reached, path.jumps, path.replans) == (outcome.reached, outcome.jumps, outcome.replans)
    assert path.failed == (not outcome.reached and outcome.status != 0)
    if noise is WILD:
        assert path.failed
    assert len(path.touchdown_times) == len(path.touchdowns)
    # each sampled jump lands exactly where the trial's next touchdown is
    np.testing.assert_allclose(path.landings, path.touchdowns[1:, :2], rtol=0, atol=1e-12)
    columns = path.columns
    for k, t in enumerate(path.touchdown_times[:-1]):  # each jump's stance starts at its touchdown
        first = np.flatnonzero(columns["jump"] == k)[0]
        assert columns["phase"][first] == 0 and 0.0 <= columns["time"][first] - t < 1.0 / 200.0 + 1e-12
    assert np.all(np.diff(columns["time"]) > 0)


def test_without_noise_every_touchdown_hits_the_plans_foothold(paper_module, planned):
    world, plan = planned
    path = followed_path(paper_module, world, plan, 5.0, NO_NOISE, 0)
    assert path.reached and path.replans == 0
    assert path.hits.all()
    targets = np.array([step.target for step in plan.steps])
    np.testing.assert_allclose(path.aims[:, 1:], targets[: len(path.aims)], atol=1e-12)
    feet = path.touchdowns[:, 1] - path.legs[:, 1] * np.sin(path.legs[:, 0])
    np.testing.assert_allclose(feet, targets[: len(feet), 1], atol=1e-9)
