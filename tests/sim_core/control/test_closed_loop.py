"""Closed-loop height control: settles at the target, respects the leg's range, rejects bad gains."""

import math

import numpy as np
import pytest

from sim_core import ControlSchedule, find_fixed_point
from sim_core.basins.sweep import find_in_place_zeta0
from sim_core.control.closed_loop import SETTLING_BAND, closed_loop_climb
from sim_core.control.height_controller import HeightController
from sim_core.model.noise import NoiseModel

PSI0 = math.radians(35.0)


@pytest.fixture(scope="module")
def hover(paper):
    return find_in_place_zeta0(paper, PSI0, guess=(-0.93, 0.3))


@pytest.fixture(scope="module")
def start(paper):
    return find_fixed_point(paper, ControlSchedule.from_degrees([(35.0, 0.9)]), 1, (-0.93, -0.2)).state


def test_pid_settles_at_the_target(paper, hover, start):
    target = 0.55 / 0.2231  # the paper's 55 cm in l0
    run = closed_loop_climb(paper, HeightController(target, hover), PSI0, start, 80, start_zeta0=0.9)
    assert run.failure is None
    settled = run.settling_jump()
    assert settled is not None and settled < 60
    assert abs(run.error[-1]) < SETTLING_BAND * (target - run.height[0])
    assert run.overshoot() < 0.1 and run.rise_time() > 0


def test_commands_stay_in_the_leg_range(paper, hover, start):
    controller = HeightController(6.0, hover, kp=2.0, ki=0.5, zeta0_min=0.85, zeta0_max=0.97)
    run = closed_loop_climb(paper, controller, PSI0, start, 40, start_zeta0=0.9)
    assert np.all((run.zeta0[1:] >= 0.85) & (run.zeta0[1:] <= 0.97))
    assert np.any(run.zeta0[1:] == 0.85), "a large error saturates the command"


def test_noisy_closed_loop_is_seeded(paper, hover, start):
    controller = HeightController(2.0, hover)
    runs = [
        closed_loop_climb(paper, controller, PSI0, start, 30, start_zeta0=0.9, noise=NoiseModel(), seed=seed)
        for seed in (4, 4, 5)
    ]
    np.testing.assert_array_equal(runs[0].height, runs[1].height)
    assert not np.array_equal(runs[0].height[: runs[2].height.size], runs[2].height[: runs[0].height.size])
