"""An MJTF study's plan and statistics (sim_core/robustness/mjtf_plan.py): every trial planned once with its
own seed however the study is split or resumed; mean and std from the moments as numpy has them."""

import math
import subprocess
import sys

import numpy as np
import pytest

from sim_core.model.failures import Failure
from sim_core.model.noise import NoiseModel, trial_seeds
from sim_core.model.presets import get_preset
from sim_core.robustness.mjtf_plan import CAPPED, jump_moments, jump_statistics, no_outcomes, plan_trials

STATS_RTOL = 1e-12  # the moments' exact variance against numpy's two-pass one


def _planned(chunks) -> list[tuple[int, int, int]]:
    return [(chunk.level, int(i), int(s)) for chunk in chunks for i, s in zip(chunk.indices, chunk.seeds, strict=True)]


def test_every_trial_is_planned_once_with_its_levels_seed():
    chunks = plan_trials(3, 10, seed=7, chunk_trials=4)
    expected = [(level, i, int(trial_seeds(7, level, 10)[i])) for level in range(3) for i in range(10)]
    assert _planned(chunks) == expected
    assert [chunk.indices.size for chunk in chunks] == [4, 4, 2] * 3, "chunks never span two levels"
    assert _planned(plan_trials(3, 10, seed=7, chunk_trials=3)) == expected, "the split does not change a seed"


def test_a_resumed_plan_holds_exactly_the_missing_trials():
    done = [{0, 1, 2, 3}, set(), set(range(10))]
    chunks = plan_trials(3, 10, seed=7, chunk_trials=4, done=done)
    whole = _planned(plan_trials(3, 10, seed=7, chunk_trials=4))
    assert _planned(chunks) == [t for t in whole if t[1] not in done[t[0]]]
    assert all(chunk.indices.size <= 4 for chunk in chunks) and {chunk.level for chunk in chunks} == {0, 1}
    with pytest.raises(ValueError, match="chunk size"):
        plan_trials(1, 10, seed=7, chunk_trials=0)


def test_a_chunk_carries_its_levels_start_to_the_trials():
    class Level:
        def __init__(self, k):
            self.schedule, self.start = np.full((1, 2), k), np.array([k, -k])

    model, noise = get_preset("paper").to_model(), NoiseModel()
    (chunk,) = plan_trials(2, 3, seed=1, chunk_trials=5)[1:]
    args = chunk.arguments(model, [Level(0.0), Level(1.0)], noise, 50)
    assert args[0] is model and args[3] is noise and args[5] == 50 and args[4] is chunk.seeds
    assert args[1][0, 0] == 1.0 and args[2].tolist() == [1.0, -1.0]


@pytest.mark.parametrize("size", [2, 3, 17, 500])
def test_statistics_from_the_moments_are_numpys(size):
    jumps = np.random.default_rng(size).integers(0, 5000, size)
    mean, std = jump_statistics(*jump_moments(jumps))
    assert mean == pytest.approx(float(np.mean(jumps)), rel=STATS_RTOL)
    assert std == pytest.approx(float(np.std(jumps, ddof=1)), rel=STATS_RTOL)


def test_statistics_of_none_or_one_trial():
    mean, std = jump_statistics(0, 0, 0)
    assert math.isnan(mean) and std == 0.0
    assert jump_statistics(*jump_moments(np.array([12]))) == (12.0, 0.0)
    assert jump_statistics(*jump_moments(np.array([4, 4, 4]))) == (4.0, 0.0), "no rounding below zero"


def test_an_empty_histogram_names_capped_and_every_failure():
    assert list(no_outcomes().items()) == [(CAPPED, 0), *((failure.code, 0) for failure in Failure)]


def test_the_plan_loads_no_kernels():
    probe = "import sys, sim_core.robustness.mjtf_plan; print('numba' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False", "the service reads a job's results without the kernels"
