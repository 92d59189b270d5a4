"""The holding state a splitting estimate starts from (sim_core/robustness/splitting_holding.py): home and
exits on the long run's scores, T_loop as jumps per exit, and a loop that cannot hold refused."""

import numpy as np
import pytest

from experiments.control_study import Config, laws_for
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError
from sim_core.robustness.splitting_holding import Loop, _exits, measure_holding
from sim_core.robustness.splitting_kernels import scores_of

ROBOT = get_preset("paper")
MODEL = ROBOT.to_model()


def test_an_exit_is_the_first_touchdown_past_the_exit_level_after_home():
    scores = np.array([3.0, 0.5, 1.5, 2.5, 2.7, 1.2, 2.1, 0.2, 1.0, 3.3, 0.1])  # 1.2 is not home: 2.1 no exit
    np.testing.assert_array_equal(_exits(scores, home=1.0, exit_level=2.0), [3, 9])


@pytest.fixture(scope="module")
def pid():
    climb, (law,) = laws_for(MODEL, Config(controllers=("pid",)), ROBOT.leg_length)
    return climb, law


def test_the_holding_state_of_a_pid_loop(pid):
    climb, law = pid
    noise = NoiseModel(velocity=0.03, pitch_drift_deg=0.0)
    loop = Loop(MODEL, law, noise, 5_000)
    holding = measure_holding(loop, climb.start, 0.9, 6_000, (0.5, 0.9), 50, np.random.default_rng(1))
    assert holding.home < holding.exit
    rescored = [scores_of(state[None, :], int(k), law.target, holding.mean, holding.whitening)[0]
                for state, k in zip(holding.exit_states, holding.exit_touchdowns, strict=True)]  # fmt: skip
    assert np.all(np.array(rescored) >= holding.exit)
    assert holding.loop_jumps == pytest.approx(6_000 / holding.exit_states.shape[0])
    assert 2 < holding.loop_jumps < 100
    assert 1 <= holding.climb_jumps < 60 and 0 <= holding.climb_failures <= 1


def test_a_loop_that_cannot_hold_is_left_to_monte_carlo(pid):
    climb, law = pid
    loop = Loop(MODEL, law, NoiseModel(velocity=0.2, pitch_drift_deg=0.0), 1_000)
    with pytest.raises(ParameterError, match="fails too often to hold") as caught:
        measure_holding(loop, climb.start, 0.9, 1_000, (0.5, 0.9), 10, np.random.default_rng(2))
    assert caught.value.field == "noise"
