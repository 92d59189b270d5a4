"""A study job's computation by kind, called directly: gait search, basin and sweep."""

import pytest

from backend.jobs.basin import BasinJobCreate
from backend.jobs.gaits import GaitSearchJobCreate
from backend.jobs.sweep import SweepJobCreate
from backend.schemas import LegIn, StateIn
from backend.services.studies import run_study
from sim_core.chunks import in_process
from tests.backend.services.test_quick_calls import EIGENVALUE_ATOL, PERIOD_1, PERIOD_1_EIGENVALUE, _strict_json


def test_run_study_gait_search(symmetric):
    progress = []
    spec = GaitSearchJobCreate(kind="gaits", controls=PERIOD_1, grid=2)
    result = run_study(spec, in_process, lambda *p: progress.append(p))
    assert result == _strict_json(result) and progress[-1] == (1, 1)
    gait = result["gaits"][0]
    assert gait["period"] == len(symmetric) and gait["motion"] == "climbing"
    assert gait["max_abs_eigenvalue"] == pytest.approx(PERIOD_1_EIGENVALUE, abs=EIGENVALUE_ATOL)


def test_run_study_basin_and_sweep_continue_undecided_cells_up_to_the_jump_limit():
    """The jobs' jump limits reach the computation: more cells converge than at the first cap."""
    near = {"controls": [LegIn(psi0_deg=30.0, zeta0=0.94)], "guess": StateIn(xdot=-0.93, ydot=-0.34), "grid": 8}

    def run(body) -> dict:
        return run_study(body, in_process, lambda *progress: None)

    cut = run(BasinJobCreate(kind="basin", jumps=10, **near))
    basin = run(BasinJobCreate(kind="basin", jumps=10, jump_limit=200, **near))
    assert (basin["jumps"], basin["jump_limit"], cut["jump_limit"]) == (10, 200, 10)
    assert basin["rounds"][0] == cut["rounds"][0] and basin["fraction"] > cut["fraction"]
    sweep = SweepJobCreate(kind="sweep", zeta0_low=0.93, zeta0_high=0.94, steps=2, basin_grid=4, basin_jumps=10,
                           basin_jump_limit=200, guess=StateIn(xdot=-0.93, ydot=-0.34))  # fmt: skip
    assert run(sweep)["basin"]["jump_limit"] == 200


def test_every_kind_warms_with_a_small_job_of_its_own(monkeypatch):
    """The job worker's start (studies.warm_job_kinds): each registered kind's ``warm`` body is a
    request it takes, and its run (MJTF's study) goes through — so a first job does not load kernels."""
    from backend.jobs import KINDS
    from backend.services import studies

    ran = []
    real_run_study = studies.run_study
    monkeypatch.setattr(studies, "run_study", lambda spec, *args: ran.append(spec.kind) or real_run_study(spec, *args))
    studies.warm_job_kinds()
    assert all(kind.warm is not None for kind in KINDS), "every kind warms"
    assert ran == [kind.name for kind in KINDS if kind.run is not None]
