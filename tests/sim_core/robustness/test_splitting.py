"""A controller's MFPT by splitting (sim_core/robustness/splitting.py) against Monte-Carlo trials of the same
loop, on noise drawn per case (no level here was chosen to suit the estimate); what it refuses."""

import math

import numpy as np
import pytest

from experiments.control_study import Config, laws_for
from sim_core.control.loop_step import LOOP_STATE_SIZE
from sim_core.control.study import control_study
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError
from sim_core.robustness.splitting import LoopMfpt, SplittingOptions, check_metastable, failure_probability, loop_mfpt
from sim_core.robustness.splitting_holding import Holding

ROBOT = get_preset("paper")
MODEL = ROBOT.to_model()


def _noise(seed: int) -> NoiseModel:
    """A noise level where 300 trials of a few hundred jumps all fail, drawn from the seed."""
    rng = np.random.default_rng(seed)
    return NoiseModel(velocity=float(rng.uniform(0.042, 0.055)), psi0_deg=float(rng.uniform(0.3, 0.8)),
                      zeta0=float(rng.uniform(0.002, 0.004)), pitch_drift_deg=0.0)  # fmt: skip


@pytest.mark.parametrize(("name", "seed"), [("pid", 21), ("lqr", 22)])
def test_splitting_agrees_with_monte_carlo_of_the_same_loop(name, seed):
    noise = _noise(seed)
    climb, (law,) = laws_for(MODEL, Config(controllers=(name,), noise=noise), ROBOT.leg_length)
    options = SplittingOptions(replicas=50, runs=16, pilot_jumps=2_000, seed=seed)
    split = loop_mfpt(MODEL, law, climb.start, 0.9, noise, options)
    (trials,) = control_study(MODEL, [law], climb.start, 0.9, 20_000, 1000 * seed, 300, noise)
    assert trials.failures == trials.trials, "the reference is every trial's failure, none censored"
    mean, half = trials.jumps_to_failure()
    low, high = split.ci95
    told = f"splitting {split.mfpt_jumps:.0f} [{low:.0f}, {high:.0f}], MC {mean:.0f} ± {half:.0f}"
    assert low < mean + half and mean - half < high, told
    assert 0.7 < split.mfpt_jumps / mean < 1.4
    assert split.lambda2_jumps == pytest.approx(1.0 / split.rate)
    payload = split.to_dict()
    assert {"mfpt_jumps", "lambda2", "discretisation_error", "cells", "seconds"} <= set(payload)
    assert payload["method"] == "splitting" and payload["discretisation_error"] is None and payload["cells"] is None
    assert payload["ci95"][0] < payload["mfpt_jumps"] < payload["ci95"][1]
    assert len(payload["splitting"]["probabilities"]) == len(payload["splitting"]["loop_jumps"]) == 16


class RandomWalk:
    """A toy loop for the AMS alone: the score walks by N(0, 0.3) a step from the exit at 0.5, home
    below 0; a step fails with chance 0.03 whatever the score (a failure from a low score, which
    no level leads to), and at 2."""

    def excursion(self, state, touchdown, holding, rng):
        scores, failed = [float(state[0])], False
        while True:
            if rng.random() < 0.03:
                failed = True
                break
            scores.append(scores[-1] + rng.normal(0.0, 0.3))
            if scores[-1] >= 2.0:
                failed = True
                break
            if scores[-1] < 0.0:
                break
        scores = np.array(scores)
        level = math.inf if failed else float(scores.max())
        return scores[:, None], touchdown + np.arange(scores.size), scores, level


def test_splitting_estimates_a_known_chance_without_bias():
    """p by AMS against plain sampling of the same excursions: a survivor that crossed the level
    by failing is copied whole (cloning it from its start instead biased p low: 0.07 for 0.18)."""
    rng = np.random.default_rng(4)
    walk = RandomWalk()
    holding = type("Exits", (), {"exit_states": np.array([[0.5]]), "exit_touchdowns": np.array([0])})()
    sampled = [math.isinf(walk.excursion(np.array([0.5]), 0, holding, rng)[3]) for _ in range(20_000)]
    truth, truth_error = np.mean(sampled), np.std(sampled) / math.sqrt(len(sampled))
    estimates = [failure_probability(walk, holding, 20, rng) for _ in range(300)]
    error = math.hypot(np.std(estimates) / math.sqrt(len(estimates)), truth_error)
    assert abs(np.mean(estimates) - truth) < 4 * error, (np.mean(estimates), truth, error)


def test_pitch_drift_is_refused_naming_the_field():
    with pytest.raises(ParameterError, match="not metastable") as caught:
        check_metastable(NoiseModel())
    assert caught.value.field == "noise.pitch_drift_deg"
    with pytest.raises(ParameterError, match="needs some noise"):
        check_metastable(NoiseModel(psi0_deg=0.0, zeta0=0.0, velocity=0.0, pitch_drift_deg=0.0))


@pytest.mark.parametrize(
    ("field", "value"),
    [("replicas", 1), ("runs", 1), ("pilot_jumps", 10), ("home_quantile", 1.5), ("exit_quantile", 0.2), ("seed", -1)],
)
def test_options_out_of_range_name_the_field(field, value):
    with pytest.raises(ParameterError) as caught:
        SplittingOptions(**{field: value})
    assert caught.value.field == field


def test_no_failure_reached_is_said_as_null_not_a_number():
    exits, touchdowns = np.zeros((1, LOOP_STATE_SIZE)), np.zeros(1, dtype=int)
    holding = Holding(np.zeros((2, 5)), np.zeros((2, 5, 5)), 1.0, 2.0, exits, touchdowns, 20.0, 0, 10.0, 0.0)
    result = LoopMfpt("lqr", 2.0, NoiseModel(pitch_drift_deg=0.0), math.inf, (math.inf, math.inf), (0.0, 0.0),
                      (holding, holding), 1.0, SplittingOptions())  # fmt: skip
    payload = result.to_dict()
    assert payload["mfpt_jumps"] is None and payload["ci95"] is None and payload["lambda2"] == 1.0
    # Two runs' long runs held SplittingOptions().pilot_jumps each with no failure: a 95% lower bound.
    held = 2 * SplittingOptions().pilot_jumps
    assert payload["failure_free_jumps"] == held and payload["mfpt_at_least_jumps"] == pytest.approx(held / 2.995732)


def test_the_lower_bound_is_wrong_at_most_5_percent_of_the_time():
    """A loop failing every m jumps on average, just under the bound the code gives for one run's
    1,000 failure-free jumps: it holds those jumps with no failure (and the bound is then too high)
    in at most 5% of the cases (geometric draws of the first failure)."""
    exits, touchdowns = np.zeros((1, LOOP_STATE_SIZE)), np.zeros(1, dtype=int)
    holding = Holding(np.zeros((2, 5)), np.zeros((2, 5, 5)), 1.0, 2.0, exits, touchdowns, 20.0, 0, 10.0, 0.0)
    options = SplittingOptions(pilot_jumps=1_000)
    bound = LoopMfpt("pid", 2.0, NoiseModel(pitch_drift_deg=0.0), math.inf, (math.inf, math.inf), (0.0,),
                     (holding,), 1.0, options).mfpt_at_least  # fmt: skip
    mean = 0.99 * bound  # the bound is too high for this loop whenever it is given
    firsts = np.random.default_rng(7).geometric(1.0 / mean, size=200_000)
    assert (firsts > options.pilot_jumps).mean() <= 0.05
