"""A climb in a world, asked for noise or the floor: noise drawn as the climb sequencer draws it
(the same seed, the same climb), none when its sigmas are zero, and the floor's cut."""

import numpy as np
import pytest

from sim_core import ControlSchedule, get_preset
from sim_core.climb.records import ClimbSetup
from sim_core.climb.sequencer import simulate_climb
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.model.noise_rules import NoiseSampler
from sim_core.model.walls import Wall
from sim_core.world.climb import climb_world
from sim_core.world.named import named_world

GAIT = ControlSchedule.from_degrees([(30, 0.87), (30, 0.9)])
NOISE = NoiseModel(psi0_deg=1.0, zeta0=0.005, velocity=0.02, pitch_drift_deg=1.0)


def test_noise_is_drawn_as_the_climb_sequencer_draws_it():
    robot = get_preset("paper")
    world = named_world("widening", robot.to_model().d_hat)
    ours = climb_world(robot.to_model(), world, GAIT, (-1.0, 0.5), 12, noise=NOISE, seed=5)
    jumps = simulate_climb(ClimbSetup(robot, world=world), lambda wall: GAIT[0 if wall is Wall.LEFT else 1],
                           (-1.0, 0.5), 12, NoiseSampler(NOISE, np.random.default_rng(5)))  # fmt: skip
    heights = [jump.start.body_height / robot.leg_length for jump in jumps]
    assert len(heights) >= 6
    assert ours.states[: len(heights), 1] == pytest.approx(heights, abs=1e-9)
    assert ours.failure is None or len(jumps) == ours.failed_jump


def test_no_sigma_is_no_noise_and_a_seed_is_its_climb(paper):
    world = named_world("narrowing", paper.d_hat)
    plain = climb_world(paper, world, GAIT, (-1.0, 0.5), 15)
    silent = climb_world(paper, world, GAIT, (-1.0, 0.5), 15, noise=NO_NOISE, seed=9)
    assert np.array_equal(plain.states, silent.states) and plain.failure == silent.failure
    once = climb_world(paper, world, GAIT, (-1.0, 0.5), 15, noise=NOISE, seed=9)
    again = climb_world(paper, world, GAIT, (-1.0, 0.5), 15, noise=NOISE, seed=9)
    other = climb_world(paper, world, GAIT, (-1.0, 0.5), 15, noise=NOISE, seed=10)
    assert np.array_equal(once.states, again.states) and not np.array_equal(once.states[:3], other.states[:3])


def test_the_floor_ends_a_descending_climb_at_its_first_touchdown_below_it(paper):
    descending = ControlSchedule.from_degrees([(30, 0.97)])
    free = climb_world(paper, named_world("parallel", paper.d_hat), descending, (-1.0, 0.0), 30)
    cut = climb_world(paper, named_world("parallel", paper.d_hat), descending, (-1.0, 0.0), 30, floor=True)
    first_below = int(np.argmax(free.states[1:, 1] < 0.0)) + 1
    assert (cut.failure.code, cut.failed_jump) == ("floor", first_below)
    assert np.array_equal(cut.states, free.states[:first_below]) and (cut.states[:, 1] >= 0.0).all()
