"""The gait atlas as a job (backend/jobs/atlas.py): its body bounded, and its result the command's."""

import pytest
from pydantic import ValidationError

from backend.jobs import JOB_KINDS, worst_case_jumps
from backend.jobs.atlas import AtlasJobCreate
from backend.schemas.job_budget import WORK_BUDGET_JUMPS
from backend.services.studies import run_study
from sim_core.chunks import in_process
from tests.cli.helpers import json_of


def test_the_jobs_atlas_is_the_commands_on_the_same_grid():
    body = AtlasJobCreate(kind="atlas", psi0_low_deg=25.0, psi0_high_deg=35.0, zeta0_low=0.88, zeta0_high=0.94,
                          rows=2, columns=3, transient=100)  # fmt: skip
    progress = []
    result = run_study(body, in_process, lambda *done: progress.append(done))
    command = json_of("atlas", "--psi0-range", "25", "35", "--zeta0-range", "0.88", "0.94", "--grid", "2", "3",
                      "--transient", "100")  # fmt: skip
    assert result == command and progress and progress[-1][0] == progress[-1][1]
    assert JOB_KINDS["atlas"] is AtlasJobCreate


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"rows": 1}, "rows"),
        ({"columns": 201}, "columns"),
        ({"zeta0_high": 0.7}, "zeta0_low"),
        ({"transient": 0}, "transient"),
    ],
)
def test_a_bad_atlas_is_refused_naming_the_field(changes, field):
    with pytest.raises(ValidationError) as refused:
        AtlasJobCreate(**({"kind": "atlas"} | changes))
    assert field in str(refused.value)


def test_the_largest_atlas_is_held_to_the_work_budget():
    largest = {"kind": "atlas", "rows": 200, "columns": 200, "transient": 10_000}
    with pytest.raises(ValidationError, match="over the limit"):
        AtlasJobCreate(**largest)
    jumps, formula = worst_case_jumps(AtlasJobCreate(kind="atlas"))
    assert 0 < jumps <= WORK_BUDGET_JUMPS and formula.startswith("rows x columns")
