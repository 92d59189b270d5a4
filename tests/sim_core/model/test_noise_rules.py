"""The noise rules (sim_core.model.noise_rules): one definition, two samplers that follow it."""

import math

import numba
import numpy as np
import pytest

from sim_core import LegControl
from sim_core.model.controls import ControlSchedule
from sim_core.model.noise import NO_NOISE, PSI0_LIMITS, ZETA0_LIMITS, NoiseModel
from sim_core.model.noise_rules import (
    NoiseSampler,
    noisy_controls,
    perturbed_controls,
    pitch_step,
    seed_trial,
)
from sim_core.model.walls import Wall, wall_of

LEG = LegControl.from_degrees(30.0, 0.9)
PITCH = math.radians(2.0)


def _sampler(noise: NoiseModel, seed: int = 0) -> NoiseSampler:
    return NoiseSampler(noise, np.random.default_rng(seed))


def test_pitch_turns_the_left_leg_up_and_the_right_leg_down():
    sampler = _sampler(NO_NOISE)
    assert sampler.controls(LEG, Wall.LEFT, PITCH).psi0 == pytest.approx(LEG.psi0 + PITCH)
    assert sampler.controls(LEG, Wall.RIGHT, PITCH).psi0 == pytest.approx(LEG.psi0 - PITCH)


def test_asymmetry_offsets_the_right_leg_only():
    sampler = _sampler(NoiseModel(0.0, 0.0, 0.0, 0.0, asymmetry_psi0_deg=2.0, asymmetry_zeta0=0.01))
    assert sampler.controls(LEG, Wall.LEFT, 0.0) == LEG
    right = sampler.controls(LEG, Wall.RIGHT, 0.0)
    assert right.psi0 == pytest.approx(LEG.psi0 + math.radians(2.0))
    assert right.zeta0 == pytest.approx(LEG.zeta0 + 0.01)


def test_zero_sigmas_give_the_exact_controls_and_draw_nothing():
    rng = np.random.default_rng(5)
    sampler = NoiseSampler(NO_NOISE, rng)
    before = rng.bit_generator.state
    assert sampler.controls(LEG, Wall.RIGHT, 0.0) == LEG
    assert sampler.pitch_step(PITCH) == PITCH
    assert sampler.state((-0.9, -0.2)) == (-0.9, -0.2)
    assert rng.bit_generator.state == before
    schedule = ControlSchedule.of(LEG).as_array()
    assert perturbed_controls(schedule, 1, 0.0, math.nan, NO_NOISE.record()) == (LEG.psi0, LEG.zeta0)


def test_controls_are_clamped_inside_the_leg_domain():
    psi0, zeta0 = noisy_controls(LEG.psi0, 0.999, False, 0.0, 0.0, 0.0, math.radians(80.0), 0.5)
    assert (psi0, zeta0) == (PSI0_LIMITS[1], ZETA0_LIMITS[1])
    psi0, zeta0 = noisy_controls(LEG.psi0, LEG.zeta0, True, math.radians(40.0), 0.0, 0.0, 0.0, -2.0)
    assert (psi0, zeta0) == (PSI0_LIMITS[0], ZETA0_LIMITS[0])
    assert 0.0 < PSI0_LIMITS[0] < PSI0_LIMITS[1] < math.pi / 2 and 0.0 < ZETA0_LIMITS[0] < ZETA0_LIMITS[1] < 1.0
    # The Python sampler clamps the same way, so a saturated leg is still a valid LegControl.
    wild = _sampler(NoiseModel(psi0_deg=20.0, zeta0=0.1, velocity=0.0, pitch_drift_deg=0.0))
    legs = [wild.controls(LegControl.from_degrees(30.0, 0.98), Wall.LEFT, 0.0) for _ in range(200)]
    assert max(leg.zeta0 for leg in legs) == ZETA0_LIMITS[1], "some draws saturate at the leg's length"


@numba.njit
def _numba_draws(seed, sigma_a, sigma_b):
    np.random.seed(seed)
    return np.random.normal(0.0, sigma_a), np.random.normal(0.0, sigma_b)


def test_both_samplers_are_the_one_rule_applied_to_their_draws():
    noise = NoiseModel(psi0_deg=1.0, zeta0=0.01, velocity=0.0, pitch_drift_deg=1.0, asymmetry_psi0_deg=0.5)
    sigma_psi0, sigma_zeta0, _, _, asymmetry_psi0, asymmetry_zeta0 = noise.record()
    schedule = ControlSchedule.of(LEG).as_array()
    seed_trial(11)
    kernel = perturbed_controls(schedule, 1, PITCH, math.nan, noise.record())
    draws = _numba_draws(11, sigma_psi0, sigma_zeta0)  # numba's generator, same seed, same order
    assert kernel == noisy_controls(LEG.psi0, LEG.zeta0, True, PITCH, asymmetry_psi0, asymmetry_zeta0, *draws)
    rng = np.random.default_rng(11)
    python = _sampler(noise, 11).controls(LEG, Wall.RIGHT, PITCH)
    draws = rng.normal(0.0, sigma_psi0), rng.normal(0.0, sigma_zeta0)
    expected = noisy_controls(LEG.psi0, LEG.zeta0, True, PITCH, asymmetry_psi0, asymmetry_zeta0, *draws)
    assert (python.psi0, python.zeta0) == expected


def test_the_python_sampler_is_reproducible_and_walks_the_pitch():
    noise = NoiseModel(psi0_deg=1.0, zeta0=0.01, velocity=0.02, pitch_drift_deg=1.0)

    def walk(seed):
        sampler, pitch, out = _sampler(noise, seed), 0.0, []
        for k in range(20):
            pitch = sampler.pitch_step(pitch)
            out.append((pitch, sampler.controls(LEG, wall_of(k), pitch)))
        return out

    assert walk(3) == walk(3)
    assert walk(3) != walk(4)
    assert len({pitch for pitch, _ in walk(3)}) == 20, "the pitch drifts every jump"
    assert pitch_step(0.0, NO_NOISE.record()) == 0.0
