"""How the study commands run (cli/studies.py): in-process unless a Dask scheduler is named, with a
progress callback; a study over zeta0 handed the model, psi0 in radians and the fixed leg; the
``--fixed-leg`` text read as one PSI0:ZETA0 pair."""

from __future__ import annotations

import math

import pytest

from cli.options import build_setup
from cli.studies import fixed_leg_of, over_zeta0, run_study
from experiments.cluster import SCHEDULER_ENV
from sim_core import LegControl, ParameterError


class Study:
    """A study that records how it was called and runs two chunks through its chunk map."""

    def __init__(self):
        self.args, self.kwargs = (), {}

    def __call__(self, *args, chunk_map, progress, **kwargs):
        self.args, self.kwargs = args, kwargs
        return chunk_map(lambda x: 2 * x, [(1,), (2,)], progress)


def test_without_a_scheduler_a_study_runs_in_process_with_progress(monkeypatch):
    monkeypatch.delenv(SCHEDULER_ENV, raising=False)
    study = Study()
    assert run_study(study, "doubling", None, "model", 0.5, jumps=3) == [2, 4], "its chunks run here, in order"
    assert study.args == ("model", 0.5) and study.kwargs == {"jumps": 3}


def test_a_study_over_zeta0_gets_the_model_psi0_in_radians_and_the_fixed_leg(monkeypatch):
    monkeypatch.delenv(SCHEDULER_ENV, raising=False)
    study, setup, fixed = Study(), build_setup("paper"), LegControl.from_degrees(30, 0.9)
    zeta0s = [0.85, 0.9]
    over_zeta0(study, "sweeping", None, setup, 35.0, zeta0s, fixed, (-0.9, -0.2), basin_grid=None)
    model, psi0, swept = study.args
    assert model == setup.model and psi0 == pytest.approx(math.radians(35.0)) and swept == zeta0s
    assert study.kwargs == {"fixed_leg": fixed, "guess": (-0.9, -0.2), "basin_grid": None}


def test_an_angle_out_of_range_is_named_before_the_study_runs():
    study = Study()
    with pytest.raises(ParameterError, match=r"^psi0:"):
        over_zeta0(study, "sweeping", None, build_setup("paper"), 95.0, [0.9], None, None)
    assert study.args == (), "it never ran"


def test_the_fixed_leg_is_one_psi0_zeta0_pair():
    assert fixed_leg_of(None) is None, "both legs sweep"
    assert fixed_leg_of("30:0.9") == LegControl.from_degrees(30, 0.9)
    with pytest.raises(ParameterError, match=r"^fixed_leg: must be one PSI0:ZETA0 pair"):
        fixed_leg_of("30:0.9,35:0.87")
    with pytest.raises(ParameterError, match=r"^controls:"):
        fixed_leg_of("30-0.9")
