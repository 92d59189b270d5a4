"""The splitting's compiled runs (sim_core/robustness/splitting_kernels.py): the score is the whitened
distance of a touchdown's features, an excursion stops home, at a failure or when full."""

import math

import numpy as np
import pytest

from experiments.control_study import Config, laws_for
from sim_core.control.loop_step import LOOP_STATE_SIZE
from sim_core.model.failures import OK
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.presets import get_preset
from sim_core.robustness.splitting_kernels import (
    FEATURES,
    TOO_LONG,
    excursion,
    features_table,
    long_run,
    score_of,
    started,
)

ROBOT = get_preset("paper")
MODEL = ROBOT.to_model().record()


@pytest.fixture(scope="module")
def lqr():
    loop, (law,) = laws_for(ROBOT.to_model(), Config(controllers=("lqr",)), ROBOT.leg_length)
    return loop, law


def _start(lqr, noise=NO_NOISE, seed=0):
    loop, law = lqr
    return started(law.kernel_args()[0], *loop.start, math.radians(law.psi0_deg), 0.9, seed, noise.record())


@pytest.mark.parametrize("seed", [1, 2])
def test_the_score_is_the_whitened_distance_per_wall(lqr, seed):
    rng = np.random.default_rng(seed)
    state, target = _start(lqr), lqr[1].target
    features = features_table(state[None, :], target)[0]
    mean = rng.normal(size=(2, FEATURES))
    whitening = rng.normal(size=(2, FEATURES, FEATURES))
    work = np.empty(FEATURES)
    for k in (0, 1, 6, 7):
        expected = np.linalg.norm(whitening[k % 2] @ (features - mean[k % 2]))
        assert score_of(state, k, target, mean, whitening, work) == pytest.approx(expected, rel=1e-12)
    at_mean = np.array([features, features])
    assert score_of(state, 3, target, at_mean, whitening, work) == 0.0


def test_an_excursion_stops_home_or_runs_full(lqr):
    law = lqr[1]
    kind, parameters = law.kernel_args()
    sigmas = NoiseModel(pitch_drift_deg=0.0).record()
    state = _start(lqr, seed=3)
    settle = np.empty((40, state.size))
    assert long_run(state, 0, kind, parameters, 4, sigmas, MODEL, settle) == (OK, 40)
    np.testing.assert_array_equal(settle[-1], state)
    mean, whitening = np.zeros((2, FEATURES)), np.zeros((2, FEATURES, FEATURES))  # every score 0
    path, scores = np.empty((50, state.size)), np.empty(50)
    home = excursion(
        state.copy(), 40, kind, parameters, 5, sigmas, MODEL, law.target, mean, whitening, 1.0, path, scores
    )
    assert home == (OK, 1) and scores[0] == 0.0
    never = excursion(state.copy(), 40, kind, parameters, 5, sigmas, MODEL, law.target, mean, whitening, -1.0, path,
                      scores)  # fmt: skip
    assert never == (TOO_LONG, 50)
    np.testing.assert_array_equal(path[0], _first_jump(state, kind, parameters, sigmas))


def _first_jump(state, kind, parameters, sigmas):
    """The excursion's first touchdown, by a run of one jump on the same seed."""
    one = np.empty((1, state.size))
    copy = state.copy()
    long_run(copy, 40, kind, parameters, 5, sigmas, MODEL, one)
    return one[0]


def test_a_failure_ends_an_excursion_with_its_status(lqr):
    law = lqr[1]
    kind, parameters = law.kernel_args()
    sigmas = NoiseModel(velocity=0.3, pitch_drift_deg=0.0).record()  # fails within jumps
    mean, whitening = np.zeros((2, FEATURES)), np.zeros((2, FEATURES, FEATURES))
    path, scores = np.empty((1000, LOOP_STATE_SIZE)), np.empty(1000)
    status, done = excursion(_start(lqr), 0, kind, parameters, 9, sigmas, MODEL, law.target, mean, whitening, -1.0,
                             path, scores)  # fmt: skip
    assert status not in (OK, TOO_LONG) and done < 1000
