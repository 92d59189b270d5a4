"""MJTF's compiled trials (sim_core.robustness.mjtf_trials): the noise rules' draw order, one trial per seed on
any number of threads, noise-free trials reaching the cap, failures reported by their status."""

import math

import numba
import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sim_core import ControlSchedule, find_fixed_point
from sim_core.model.failures import OK, Failure
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NO_NOISE, NoiseModel, trial_seeds
from sim_core.model.noise_rules import disturbed_state, perturbed_controls, pitch_step, seed_trial
from sim_core.model.stride import jump
from sim_core.robustness.mjtf_trials import run_trials, trial

CAP = 300
NOISE = NoiseModel()  # the defaults: most trials fail before the cap, some reach it
SEEDS = trial_seeds(1, 0, 16)
# Every source on, each strong enough that a draw taken out of order changes when a trial fails.
EVERY_SOURCE = NoiseModel(
    psi0_deg=1.0, zeta0=0.005, velocity=0.05, pitch_drift_deg=0.5, asymmetry_psi0_deg=0.5, asymmetry_zeta0=0.005
)


@pytest.fixture(scope="module")
def gait(paper, symmetric):
    """The paper's period-1 gait (psi0 = 30°, zeta0 = 0.9): where trials start."""
    return find_fixed_point(paper, symmetric, 1, (-1.0, 0.0))


def _python_trial(model, schedule, start, noise, seed, cap):
    """A trial spelled out in Python from the same compiled rules, in the order the module documents:
    the first leg at launch; per jump a pitch step, the next leg's controls, the jump, the state noise."""
    noise = noise.record()
    seed_trial(seed)
    xdot, ydot = start
    pitch = 0.0
    psi0, zeta0 = perturbed_controls(schedule, 0, pitch, math.nan, noise)
    for k in range(cap):
        next_pitch = pitch_step(pitch, noise)
        next_psi0, next_zeta0 = perturbed_controls(schedule, k + 1, next_pitch, math.nan, noise)
        status, xdot, ydot, *_ = jump(
            xdot, ydot, psi0, zeta0, next_psi0, next_zeta0, model.record(), np.empty((0, STATE_SIZE))
        )
        if status != OK:
            return k, status
        xdot, ydot = disturbed_state(xdot, ydot, noise)
        pitch, psi0, zeta0 = next_pitch, next_psi0, next_zeta0
    return cap, OK


def test_a_trial_draws_in_the_noise_rules_order(paper, symmetric, gait):
    schedule = symmetric.as_array()
    for seed in SEEDS[:8]:
        compiled = trial(*gait.state, schedule, seed, CAP, EVERY_SOURCE.record(), paper.record())
        assert compiled == _python_trial(paper, schedule, gait.state, EVERY_SOURCE, seed, CAP), f"seed {seed}"


def test_the_batch_is_one_trial_per_seed_on_any_number_of_threads(paper, symmetric, gait):
    schedule = symmetric.as_array()
    jumps, status = run_trials(paper, schedule, gait.state, NOISE, SEEDS, CAP)
    one_by_one = [trial(*gait.state, schedule, seed, CAP, NOISE.record(), paper.record()) for seed in SEEDS]
    assert_array_equal(jumps, [j for j, _ in one_by_one])
    assert_array_equal(status, [s for _, s in one_by_one])
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        single = run_trials(paper, schedule, gait.state, NOISE, SEEDS, CAP)
    finally:
        numba.set_num_threads(threads)
    assert_array_equal(single[0], jumps)
    assert_array_equal(single[1], status)
    other = run_trials(paper, schedule, gait.state, NOISE, trial_seeds(2, 0, SEEDS.size), CAP)
    assert not np.array_equal(other[0], jumps), "other seeds, other trials"


def test_noisy_trials_end_in_a_failure_or_at_the_cap(paper, symmetric, gait):
    jumps, status = run_trials(paper, symmetric.as_array(), gait.state, NOISE, SEEDS, CAP)
    assert np.all((jumps == CAP) == (status == OK)), "capped trials, and only they, report OK"
    assert 0 < np.count_nonzero(status == OK) < SEEDS.size, "the defaults fail some trials, not all"
    assert {Failure(s) for s in status[status != OK]} <= set(Failure)


def test_without_noise_a_trial_stays_on_its_gait_to_the_cap(paper, symmetric, gait):
    jumps, status = run_trials(paper, symmetric.as_array(), gait.state, NO_NOISE, SEEDS[:3], 50)
    assert_array_equal(jumps, 50)
    assert_array_equal(status, OK)


def test_a_failing_first_jump_completes_none(paper):
    """Outside the friction cone (mu = 2: 63.4°) the first stance slips."""
    steep = ControlSchedule.from_degrees([(70.0, 0.9)])
    jumps, status = run_trials(paper, steep.as_array(), (-0.93, -0.17), NO_NOISE, SEEDS[:2], CAP)
    assert_array_equal(jumps, 0)
    assert_array_equal(status, Failure.SLIP)
