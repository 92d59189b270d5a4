"""MJTF's trials in a world: on parallel walls the map's trials, draw for draw, but for the two
endings a world adds (the floor, a flight past its cap); in a world they end as its sides say."""

import math

import numpy as np
import pytest

from sim_core.model.failures import FLOOR, NO_TOUCHDOWN, OK, SLIP
from sim_core.model.noise import NoiseModel
from sim_core.robustness.mjtf import level_starts, mjtf_study
from sim_core.robustness.mjtf_trials import run_trials
from sim_core.robustness.world_trials import run_world_trials
from sim_core.world.world import Side, World, parallel


@pytest.fixture(scope="module")
def level(paper):
    return level_starts(paper, math.radians(30), [0.9])[0]


def test_on_parallel_walls_each_trial_is_the_maps_until_a_world_ends_it(paper, level):
    seeds = np.arange(1, 121, dtype=np.uint64) * 7919
    noise = NoiseModel(psi0_deg=1.0, velocity=0.02)
    theirs, their_status = run_trials(paper, level.schedule, level.start, noise, seeds, 400)
    walls = parallel(paper.d_hat)
    ours, our_status = run_world_trials(paper, level.schedule, level.start, noise, seeds, 400, walls, 0.0)
    ended_by_world = np.isin(our_status, (FLOOR, NO_TOUCHDOWN))
    assert np.array_equal(ours[~ended_by_world], theirs[~ended_by_world])
    assert np.array_equal(our_status[~ended_by_world], their_status[~ended_by_world])
    assert (ours[ended_by_world] <= theirs[ended_by_world]).all()
    assert (~ended_by_world).sum() > 60 and (our_status == OK).any()


def test_a_chute_with_no_grip_above_the_start_ends_every_trial_there(paper, level):
    greasy_above = World(
        Side(np.array([[-1.21, 0.0], [-1.21, 0.3], [-1.21, 9.0]]), np.array([np.nan, 0.0])),
        Side(np.array([[1.21, 0.0], [1.21, 0.5], [1.21, 9.0]]), np.array([np.nan, 0.0])),
        "greasy above",
    )
    seeds = np.arange(1, 41, dtype=np.uint64)
    jumps, status = run_world_trials(paper, level.schedule, level.start, NoiseModel(), seeds, 200, greasy_above, 0.0)
    assert (status == SLIP).all() and jumps.max() <= 3, "a climbing gait reaches the greasy part in a jump or two"


def test_the_study_names_its_world_and_the_foot(paper):
    study = mjtf_study(paper, math.radians(30), [0.9], noise=NoiseModel(), trials=4, cap=20, seed=3,
                       world=parallel(paper.d_hat), foot_y=0.5)  # fmt: skip
    document = study.to_dict()
    assert document["world"] == "parallel" and document["foot_y"] == 0.5
    on_walls = mjtf_study(paper, math.radians(30), [0.9], noise=NoiseModel(), trials=4, cap=20).to_dict()
    assert "world" not in on_walls and "foot_y" not in on_walls, "parkour mjtf's output as it was"
