"""MJTF Monte-Carlo studies: seeded and chunk-independent, noise-free runs survive, Fig. 11's trend
(the compiled trials: test_mjtf_trials.py)."""

import math

import numpy as np
import pytest

from sim_core import ParameterError
from sim_core.model.failures import OK
from sim_core.model.noise import NO_NOISE, NoiseModel
from sim_core.robustness.mjtf import CAPPED, mjtf_study

PSI0 = math.radians(30.0)
GUESS = (-0.93, -0.2)


def _study(paper, **options):
    zeta0s = options.pop("zeta0s", [0.86, 0.95])
    settings = {"noise": NoiseModel(), "trials": 24, "cap": 400, "seed": 7, "guess": GUESS} | options
    return mjtf_study(paper, PSI0, zeta0s, **settings)


def test_same_seed_same_numbers_however_the_trials_are_chunked(paper):
    """Each trial's seed is fixed by (seed, level, index): the chunks do not change the numbers
    (the threads neither: test_mjtf_trials.py)."""
    first = _study(paper)
    split = _study(paper, chunk_trials=5)
    for a, b in zip(first.levels, split.levels, strict=True):
        np.testing.assert_array_equal(a.jumps, b.jumps)
        np.testing.assert_array_equal(a.status, b.status)
    other_seed = _study(paper, seed=8)
    assert not np.array_equal(first.levels[0].jumps, other_seed.levels[0].jumps)


def test_more_energy_survives_longer(paper):
    """Paper Fig. 11: MJTF rises with the stored energy (smaller zeta0)."""
    study = _study(paper)
    high_energy, low_energy = study.levels
    assert high_energy.energy > low_energy.energy
    assert high_energy.ci95[0] > low_energy.ci95[1], (high_energy.ci95, low_energy.ci95)


def test_without_noise_every_trial_reaches_the_cap(paper):
    study = _study(paper, noise=NO_NOISE, trials=3, cap=50, zeta0s=[0.9])
    (level,) = study.levels
    assert (level.jumps == 50).all() and (level.status == OK).all()
    assert level.histogram()[CAPPED] == 3 and level.mean == 50 and level.std == 0


def test_outcomes_account_for_every_trial(paper):
    level = _study(paper, cap=40).levels[1]
    assert sum(level.histogram().values()) == level.jumps.size == 24
    assert (level.jumps <= 40).all()
    assert level.to_dict()["jumps"] == level.jumps.tolist()


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"trials": -1}, "trials"),
        ({"trials": 0}, "trials"),
        ({"cap": 10**9}, "cap"),
        ({"seed": -2}, "seed"),
    ],
)
def test_bad_specs_are_rejected(paper, options, field):
    with pytest.raises(ParameterError, match=f"^{field}:"):
        _study(paper, **options)


@pytest.mark.parametrize(
    ("options", "field"),
    [({"psi0_deg": -1.0}, "noise.psi0_deg"), ({"velocity": math.nan}, "noise.velocity")],
)
def test_bad_noise_is_rejected(options, field):
    with pytest.raises(ParameterError, match=f"^{field}:"):
        NoiseModel(**options)
