"""The planner's landing checks: a foot keeps the placement law's margins from a foothold's ends
and inside its cone exactly where the law's own (compiled) check says so."""

import math

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.control.placement import _end_margin
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.planning.landings import noise_draws, with_margins
from sim_core.world.geometry import pack
from sim_core.world.random_world import random_world


def test_margins_agree_with_the_laws_own_check_on_random_feet():
    world, settings, rng = random_world(6), PlacementSettings(), np.random.default_rng(6)
    sides = pack(world, 2.0)
    count = 400
    side = rng.integers(0, 2, count)
    segment = np.array([rng.integers(0, sides.counts[s] - 1) for s in side])
    low, high = sides.points[side, segment, 1], sides.points[side, segment + 1, 1]
    foot_y = low + rng.uniform(-0.05, 1.05, count) * (high - low)
    psi0 = np.radians(rng.uniform(0.0, 80.0, count))
    ours = with_margins(sides, side, segment, foot_y, psi0, settings)
    for i in range(count):
        along, most = _end_margin(sides, side[i], segment[i], foot_y[i])
        half = math.atan(sides.friction[side[i], segment[i] + 1])
        cone = half - abs(psi0[i] - sides.beta[side[i], segment[i] + 1])
        expected = along >= min(settings.end_margin, most) and cone >= min(math.radians(settings.cone_margin_deg),
                                                                             0.5 * half)  # fmt: skip
        assert bool(ours[i]) == expected
    assert 0 < ours.sum() < count, "some feet keep the margins and some do not"


def test_the_draws_are_the_nominal_then_the_noise():
    draws = noise_draws(NoiseModel(), 8, 3)
    assert draws.shape == (9, 5) and not draws[0].any() and draws[1:].std() > 0.0
    assert not noise_draws(NO_NOISE, 8, 3).any()
