"""sim_core/model/noisy_map.py: the mid-chute step is the Poincaré map's jump cut in two, noisy paths
on it fail as MJTF's trials do, the spread of a pair's landings is matched to the grid, and each
pair's transitions add up."""

import math

import numpy as np
import pytest

from sim_core import find_fixed_point
from sim_core.model.failures import OK
from sim_core.model.integrate import STATE_SIZE
from sim_core.model.noise import NoiseModel
from sim_core.model.noisy_map import (
    first_jumps,
    interpolation_variance,
    matched_spread,
    middle_step,
    pair_transitions,
    sampled_paths,
)
from sim_core.model.stride import jump
from sim_core.robustness.mfpt_grid import quadrature
from sim_core.robustness.mjtf import mjtf_study

NO_RECORD = np.empty((0, STATE_SIZE))


@pytest.fixture(scope="module")
def gait(paper, symmetric):
    return find_fixed_point(paper, symmetric, 1, (-0.93, -0.2))


def to_middle_of(paper, state, psi0, zeta0, psi0_draw=0.0, zeta0_draw=0.0):
    starts = np.empty((1, 3))
    status = np.empty(1, dtype=np.int64)
    first_jumps(state[0], state[1], psi0, zeta0, np.array([[psi0_draw, zeta0_draw]]), paper.record(), starts, status)
    assert status[0] == OK
    return starts[0]


@pytest.mark.parametrize(("pitch_deg", "psi0_deg", "zeta0"), [(0.0, 30.0, 0.9), (2.0, 30.0, 0.9), (-3.0, 33.0, 0.87)])
def test_two_halves_of_a_jump_are_the_map_s_jump(paper, gait, pitch_deg, psi0_deg, zeta0):
    # middle -> wall -> stance -> middle, at the next leg's pitch p, is the map's jump from the
    # touchdown the first half reaches, with next controls (psi0 + p, zeta0).
    psi0, pitch = math.radians(psi0_deg), math.radians(pitch_deg)
    state = gait.state
    middle = to_middle_of(paper, state, psi0, zeta0)
    status, x1, y1 = middle_step(
        middle[0], middle[1], pitch, psi0, zeta0, 0.0, 0.0, 0.0, 0.0, paper.record(), NO_RECORD
    )
    assert status == OK
    status, touchdown_x, touchdown_y, *_ = jump(
        state[0], state[1], psi0, zeta0, psi0 + pitch, zeta0, paper.record(), NO_RECORD
    )
    assert status == OK
    expected = to_middle_of(paper, (touchdown_x, touchdown_y), psi0 + pitch, zeta0)
    np.testing.assert_allclose((x1, y1), expected[:2], rtol=1e-12, atol=1e-12)


def test_noisy_paths_on_the_middle_section_last_as_long_as_mjtf_trials(paper):
    # The same noise, drawn independently: the mean jumps to failure agree within their intervals.
    noise, psi0, zeta0 = NoiseModel(), math.radians(30.0), 0.96
    level = mjtf_study(paper, psi0, [zeta0], noise=noise, trials=600, cap=5000, seed=7, guess=(-0.93, 0.2)).levels[0]
    sigma_psi0, sigma_zeta0, sigma_velocity, sigma_pitch, _, _ = noise.record()
    rng = np.random.default_rng(11)
    count, steps = 600, 2000
    starts = np.empty((count, 3))
    status = np.empty(count, dtype=np.int64)
    leg = rng.standard_normal((count, 2)) * [sigma_psi0, sigma_zeta0]
    first_jumps(*level.start, psi0, zeta0, leg, paper.record(), starts, status)
    draws = rng.standard_normal((count, steps, 5)) * [
        sigma_pitch,
        sigma_psi0,
        sigma_zeta0,
        sigma_velocity,
        sigma_velocity,
    ]
    visited = np.empty((count, steps, 3))
    done = np.empty(count, dtype=np.int64)
    sampled_paths(starts, psi0, zeta0, draws, paper.record(), visited, done)
    jumps = np.where(status == OK, 1 + done, 0)
    assert np.all(done < steps), "every path fails"
    spread = math.hypot(level.std / math.sqrt(level.jumps.size), jumps.std() / math.sqrt(count))
    assert abs(jumps.mean() - level.mean) < 3 * spread, (jumps.mean(), level.mean)


@pytest.mark.parametrize("spacing", [0.01, 0.03])
def test_matched_spread_keeps_the_mean_and_the_variance_once_shared_among_nodes(spacing):
    rng = np.random.default_rng(5)
    axis = np.arange(0.0, 2.0 + spacing / 2, spacing)
    values = rng.normal(1.0, 0.04, 64)
    weights = np.full(64, 1 / 64)
    ok = np.ones(64, dtype=bool)
    ok[:4] = False  # failed draws take no part
    mean, variance = np.average(values[ok], weights=weights[ok]), np.cov(values[ok], aweights=weights[ok], bias=True)
    shrunk = values.copy()
    matched_spread(shrunk, weights, ok, axis)
    assert np.average(shrunk[ok], weights=weights[ok]) == pytest.approx(mean, abs=1e-14)
    added = np.average([interpolation_variance(v, axis) for v in shrunk[ok]], weights=weights[ok])
    after = np.cov(shrunk[ok], aweights=weights[ok], bias=True) + added
    assert after == pytest.approx(variance, rel=0.01)
    assert np.all(shrunk[~ok] == values[~ok])


def test_a_spread_smaller_than_the_grid_collapses_to_its_mean_rather_than_grow():
    axis = np.linspace(0.0, 2.0, 11)  # nodes 0.2 apart, landings 0.01 apart
    values = np.array([1.09, 1.1, 1.11])
    matched_spread(values, np.full(3, 1 / 3), np.ones(3, dtype=bool), axis)
    np.testing.assert_allclose(values, 1.1)


def test_a_pair_s_transitions_and_losses_add_up_to_one(paper, gait):
    psi0, zeta0 = math.radians(30.0), 0.9
    middle = to_middle_of(paper, gait.state, psi0, zeta0)
    xdots = np.linspace(middle[0] - 0.3, middle[0] + 0.3, 13)
    ydots = np.linspace(middle[1] - 0.3, middle[1] + 0.3, 13)
    pitches = np.radians(np.arange(-16, 17) * 2.0)  # -32 ... 32 degrees
    state_of = np.arange(pitches.size * 169).reshape(pitches.size, 169)
    state_of[:, ::11] = -1  # some nodes outside the chain (not those around the gait): their share is lost
    draws, weights = quadrature((math.radians(0.5), 0.003, 0.01, 0.01), (4, 3, 2, 2))
    nodes = np.array([6 + 6 * 13, 0, 168, 6 + 6 * 13])
    layers = np.array([16, 16, 16, 31])  # zero pitch, and 30 degrees
    width = draws.shape[0] * 4
    cols = np.empty((4, width), dtype=np.int64)
    probabilities = np.empty((4, width))
    counts = np.empty(4, dtype=np.int64)
    failed, escaped = np.empty(4), np.empty(4)
    pair_transitions(nodes, layers, xdots, ydots, pitches, state_of, psi0, zeta0, draws, weights,
                     paper.record(), cols, probabilities, counts, failed, escaped)  # fmt: skip
    for pair in range(4):
        kept = probabilities[pair, : counts[pair]]
        assert np.all(kept > 0) and np.all(np.diff(cols[pair, : counts[pair]]) > 0)
        assert kept.sum() + failed[pair] + escaped[pair] == pytest.approx(1.0, abs=1e-12)
        reached = cols[pair, : counts[pair]]
        assert np.all(reached // 169 == layers[pair]), "a jump lands on the layer of the pitch its leg saw"
    assert failed[0] == 0.0 and escaped[0] < 0.5, "from the gait, at zero pitch, nothing fails"
    assert failed[3] > 0.5, "at 30 degrees of pitch the leg slips"
