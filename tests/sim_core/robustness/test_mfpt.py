"""sim_core/robustness/mfpt.py: what the chain refuses, and the MFPT against Monte-Carlo MJTF at a level and a
noise no default was tuned on, and where Monte-Carlo saturates."""

import math
from dataclasses import replace

import pytest

from sim_core.model.controls import LegControl
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.robustness.mfpt import mfpt
from sim_core.robustness.mfpt_grid import ChainGrid
from sim_core.robustness.mjtf import level_starts, mjtf_study

GUESS = (-0.93, 0.2)


@pytest.mark.parametrize(
    ("noise", "field"),
    [
        (NoiseModel(asymmetry_psi0_deg=0.5), "noise.asymmetry_psi0_deg"),
        (NoiseModel(asymmetry_zeta0=0.01), "noise.asymmetry_zeta0"),
    ],
)
def test_an_asymmetry_the_chain_cannot_hold_is_refused_naming_it(paper, noise, field):
    with pytest.raises(ParameterError) as error:
        mfpt(paper, LegControl(math.radians(30), 0.9), noise, start=(-0.93, -0.2))
    assert error.value.field == field


def test_a_chute_too_narrow_for_the_middle_section_is_refused(paper):
    narrow = replace(paper, d_hat=1.9)
    with pytest.raises(ParameterError, match="d_hat > 2"):
        mfpt(narrow, LegControl(math.radians(30), 0.9), NoiseModel(), start=(-0.93, -0.2))


@pytest.mark.parametrize("start", [(0.5, 0.1), (math.nan, 0.0), (1.0,)])
def test_a_bad_start_is_refused(paper, start):
    with pytest.raises(ParameterError) as error:
        mfpt(paper, LegControl(math.radians(30), 0.9), NoiseModel(), start=start)
    assert error.value.field == "start"


@pytest.mark.slow
def test_mfpt_agrees_with_monte_carlo_at_an_unseen_level_and_noise(paper):
    # Neither this level nor this noise was used to choose the grid's defaults (the Fig. 11 levels
    # at the default noise were); a coarse grid keeps the test short.
    noise = NoiseModel(psi0_deg=0.6, zeta0=0.004, velocity=0.015, pitch_drift_deg=0.6)
    psi0, zeta0 = math.radians(31.0), 0.94
    level = mjtf_study(paper, psi0, [zeta0], noise=noise, trials=1000, cap=20_000, seed=3, guess=GUESS).levels[0]
    progress = []
    result = mfpt(
        paper,
        LegControl(psi0, zeta0),
        noise,
        start=level.start,
        grid=ChainGrid(velocity_nodes=16, pitch_spacing=1.0, paths=200, path_jumps=2000),
        progress=lambda done, total: progress.append((done, total)),
    )
    low, high = level.ci95
    assert 0.9 * low < result.mfpt_jumps < 1.1 * high, (result.mfpt_jumps, level.mean, level.ci95)
    assert result.discretisation_error < 0.1
    assert 0.9 < result.lambda2 < 1.0 and result.lambda2_jumps < result.mfpt_jumps * 1.5
    assert progress[-1][0] == progress[-1][1], "progress reaches its total"
    payload = result.to_dict()
    assert {"mfpt_jumps", "lambda2", "discretisation_error", "cells", "seconds"} <= set(payload)
    assert len(payload["grids"]) == 2 and payload["grids"][1]["velocity_nodes"] == 16


def test_without_drift_the_chain_is_one_layer_and_the_gait_lasts_far_beyond_monte_carlo(paper):
    # The saturated regime of issue 28: no pitch drift, velocity noise 0.05; every Monte-Carlo
    # trial of a few thousand jumps survives, and the chain puts a number on how long it lasts.
    psi0, zeta0 = math.radians(30.0), 0.9
    start = level_starts(paper, psi0, [zeta0], guess=GUESS)[0].start
    noise = NoiseModel(pitch_drift_deg=0.0, velocity=0.05)
    result = mfpt(
        paper, LegControl(psi0, zeta0), noise, start=start, grid=ChainGrid(velocity_nodes=24, paths=50, path_jumps=500)
    )
    assert result.mfpt_jumps > 1e5
    assert result.lambda2 > 1 - 1e-5
