"""Batch jobs' bodies (each kind's module in backend/jobs/, their union in backend/jobs/__init__.py):
the kinds told apart by ``kind`` (MJTF when it is left out), each bounded field by field and by
one work budget in jumps, and a job read back."""

import dataclasses
import datetime
from typing import Literal

import pytest

from backend.jobs import JOB_KINDS, KINDS, JobCreate, UnreadableSpec, job_kind, worst_case_jumps
from backend.jobs.basin import BasinJobCreate
from backend.jobs.control_study import ControlStudyJobCreate
from backend.jobs.gaits import GaitSearchJobCreate
from backend.jobs.mfpt import MfptJobCreate
from backend.jobs.mjtf import MJTFJobCreate
from backend.jobs.sweep import SweepJobCreate
from backend.jobs.viability import ViabilityJobCreate
from backend.schemas import NoiseIn
from backend.schemas.job_budget import WORK_BUDGET_JUMPS
from backend.schemas.jobs import JobOut, JobResults, JobState
from sim_core.model.noise import ASYMMETRY_LIMITS, SIGMA_LIMITS, NoiseModel
from tests.backend.schemas.refusals import LEG, START, accepted, refusal_messages, refused

MJTF = {"zeta0s": [0.9]}
SWEEP = {"kind": "sweep"}
BASIN = {"kind": "basin", "controls": [LEG]}
GAITS = {"kind": "gaits", "controls": [LEG]}
CONTROL = {"kind": "control-study"}
MFPT = {"kind": "mfpt"}
VIABILITY = {"kind": "viability"}
BODIES = {"mjtf": MJTF, "sweep": SWEEP, "basin": BASIN, "gaits": GAITS, "control-study": CONTROL, "mfpt": MFPT,
          "loop-mfpt": {"kind": "loop-mfpt"}, "viability": VIABILITY, "atlas": {"kind": "atlas"},
          "foothold-study": {"kind": "foothold-study", "random_worlds": {"count": 1}, "goal_height_m": 0.5},
          "plan": {"kind": "plan", "world_id": 1, "goal_height_m": 0.5},
          "world-mjtf": {"kind": "world-mjtf", "world_id": 1, "controls": [LEG]},
          "reach": {"kind": "reach", "world_id": 1}}  # fmt: skip


@pytest.mark.parametrize("kind", JOB_KINDS)
def test_a_job_is_read_as_the_kind_it_names(kind):
    job = accepted(JobCreate, BODIES[kind] | {"kind": kind})
    assert type(job) is JOB_KINDS[kind] and job.kind == kind


def test_a_job_without_a_kind_is_mjtf_and_an_unknown_kind_is_refused():
    assert type(accepted(JobCreate, MJTF)) is MJTFJobCreate
    assert refused(JobCreate, {"kind": "no-such-kind"}) == [()]
    assert "'mjtf', 'sweep', 'basin', 'gaits'" in refusal_messages(JobCreate, {"kind": "no-such-kind"})


def test_errors_name_the_kind_then_the_field():
    assert refused(JobCreate, {"zeta0s": [0.9, 1.0]}) == [("mjtf", "zeta0s", 1)]
    assert refused(JobCreate, BASIN | {"controls": [LEG | {"zeta0": 0.0}]}) == [("basin", "controls", 0, "zeta0")]
    assert refused(JobCreate, GAITS | {"trials": 3}) == [("gaits", "trials")]


def test_noise_defaults_are_the_simulators():
    noise = NoiseIn()
    assert NoiseModel(**noise.model_dump()) == NoiseModel(), "the request's defaults are sim_core's"
    assert set(NoiseIn.model_fields) == {field.name for field in dataclasses.fields(NoiseModel)}


@pytest.mark.parametrize("field", list(SIGMA_LIMITS))
def test_a_noise_sigma_is_in_zero_to_its_limit(field):
    limit = SIGMA_LIMITS[field]
    assert getattr(accepted(NoiseIn, {field: 0.0}), field) == 0.0
    assert getattr(accepted(NoiseIn, {field: limit * 0.999}), field) == limit * 0.999
    assert refused(NoiseIn, {field: limit}) == [(field,)]
    assert refused(NoiseIn, {field: -1e-9}) == [(field,)]


@pytest.mark.parametrize("field", list(ASYMMETRY_LIMITS))
def test_a_noise_asymmetry_is_within_plus_or_minus_its_limit(field):
    limit = ASYMMETRY_LIMITS[field]
    assert getattr(accepted(NoiseIn, {field: -limit * 0.999}), field) == -limit * 0.999
    assert refused(NoiseIn, {field: limit}) == [(field,)]
    assert refused(NoiseIn, {field: -limit}) == [(field,)]


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("zeta0s", [0.8 + 0.001 * k for k in range(100)], [0.8 + 0.001 * k for k in range(101)]),
        ("zeta0s", [0.9], []),
        ("trials", 1, 0),
        ("cap", 1, 0),
        ("cap", 100_000, 100_001),
        ("seed", 2**63 - 1, 2**63),
        ("seed", 0, -1),
        ("psi0_deg", 89.9, 90.0),
    ],
)
def test_an_mjtf_job_outside_its_range_is_refused_naming_the_field(field, inside, outside):
    assert getattr(accepted(MJTFJobCreate, MJTF | {field: inside}), field) == inside
    assert refused(MJTFJobCreate, MJTF | {field: outside}) == [(field,)]


def test_mjtf_levels_are_distinct():
    assert refused(MJTFJobCreate, {"zeta0s": [0.9, 0.88, 0.9]}) == [("zeta0s",)]
    assert "distinct" in refusal_messages(MJTFJobCreate, {"zeta0s": [0.9, 0.9]})


@pytest.mark.parametrize(
    ("schema", "at_budget", "over", "formula"),
    [
        (MJTFJobCreate, {"zeta0s": [0.8, 0.9, 0.95, 0.96, 0.97], "trials": 100_000, "cap": 1000}, {"cap": 1001},
         "levels x trials x cap"),
        (SweepJobCreate, SWEEP | {"steps": 500, "basin_grid": 200, "basin_jumps": 25}, {"basin_jumps": 26},
         "steps x basin_grid² x basin_jumps"),
        (BasinJobCreate, BASIN | {"grid": 1000, "jumps": 500}, {"jumps": 501}, "grid² x jumps"),
        (BasinJobCreate, BASIN | {"grid": 100, "jump_limit": 50_000}, {"jump_limit": 50_001}, "grid² x jump_limit"),
        (SweepJobCreate, SWEEP | {"steps": 10, "basin_grid": 100, "basin_jump_limit": 5000},
         {"basin_jump_limit": 5001}, "steps x basin_grid² x basin_jump_limit"),
        (ControlStudyJobCreate, CONTROL | {"controllers": ["pid", "lqr"], "seeds": 50_000, "jumps": 5000},
         {"jumps": 5001}, "controllers x seeds x jumps"),
    ],
    ids=["mjtf", "sweep", "basin", "basin-limit", "sweep-limit", "control-study"],
)  # fmt: skip
def test_a_job_at_the_work_budget_is_taken_and_one_jump_over_is_refused_naming_the_formula(
    schema, at_budget, over, formula
):
    accepted(schema, at_budget)
    message = refusal_messages(schema, at_budget | over)
    assert f"over the limit of {WORK_BUDGET_JUMPS:.3g}" in message and f"({formula})" in message


@pytest.mark.parametrize(
    ("schema", "body", "limit", "first_cap"),
    [(BasinJobCreate, BASIN, "jump_limit", "jumps"), (SweepJobCreate, SWEEP, "basin_jump_limit", "basin_jumps")],
)
def test_a_basin_jump_limit_is_none_or_at_least_the_first_cap(schema, body, limit, first_cap):
    assert getattr(accepted(schema, body), limit) is None, "no continuation unless asked"
    assert getattr(accepted(schema, body | {first_cap: 60, limit: 60}), limit) == 60
    message = refusal_messages(schema, body | {first_cap: 60, limit: 59})
    assert f"{limit} must be at least {first_cap}, got 59 < 60" in message


def test_a_sweep_runs_from_a_lower_to_a_higher_zeta0():
    assert accepted(SweepJobCreate, SWEEP | {"zeta0_low": 0.9, "zeta0_high": 0.9001}).steps == 30
    message = refusal_messages(SweepJobCreate, SWEEP | {"zeta0_low": 0.9, "zeta0_high": 0.9})
    assert "zeta0_low must be below zeta0_high, got 0.9 >= 0.9" in message


@pytest.mark.parametrize(("grid", "taken"), [(0, True), (1, False), (2, True), (200, True)])
def test_a_sweeps_basin_grid_is_none_or_at_least_2(grid, taken):
    body = SWEEP | {"basin_grid": grid}
    if taken:
        assert accepted(SweepJobCreate, body).basin_grid == grid
    else:
        assert "basin_grid must be 0 (no basins) or at least 2" in refusal_messages(SweepJobCreate, body)


@pytest.mark.parametrize(
    ("schema", "body", "field", "inside", "outside"),
    [
        (SweepJobCreate, SWEEP, "steps", 2, 1),
        (SweepJobCreate, SWEEP, "basin_grid", 200, 201),
        (SweepJobCreate, SWEEP, "basin_jumps", 1, 0),
        (BasinJobCreate, BASIN, "grid", 2, 1),
        (BasinJobCreate, BASIN, "jumps", 1, 0),
        (BasinJobCreate, BASIN, "tolerance", 9.99, 10.0),
        (BasinJobCreate, BASIN, "tolerance", 1e-9, 0.0),
        (BasinJobCreate, BASIN, "period", 16, 17),
        (BasinJobCreate, BASIN | {"grid": 2}, "jump_limit", 100_000, 100_001),
        (SweepJobCreate, SWEEP | {"basin_grid": 2}, "basin_jump_limit", 100_000, 100_001),
        (GaitSearchJobCreate, GAITS, "grid", 20, 21),
        (GaitSearchJobCreate, GAITS, "grid", 1, 0),
        (GaitSearchJobCreate, GAITS, "period", 1, 0),
        (ControlStudyJobCreate, CONTROL, "target_m", 2.0, 2.0001),
        (ControlStudyJobCreate, CONTROL, "target_m", 1e-9, 0.0),
        (ControlStudyJobCreate, CONTROL, "psi0_deg", 10.0, 9.99),
        (ControlStudyJobCreate, CONTROL, "psi0_deg", 60.0, 60.01),
        (ControlStudyJobCreate, CONTROL, "start_zeta0", 0.999, 1.0),
        (ControlStudyJobCreate, CONTROL, "jumps", 1, 0),
        (ControlStudyJobCreate, CONTROL, "jumps", 100_000, 100_001),
        (ControlStudyJobCreate, CONTROL, "seeds", 1, 0),
        (ControlStudyJobCreate, CONTROL, "seeds", 100_000, 100_001),
        (ControlStudyJobCreate, CONTROL, "seed0", 0, -1),
        (ControlStudyJobCreate, CONTROL, "seed0", 2**32 - 100_000, 2**32 - 99_999),
        (ControlStudyJobCreate, CONTROL, "controllers", ["pid-pitch"], ["pid-pitch", "pid-pitch"]),
        (ControlStudyJobCreate, CONTROL, "controllers", ["lqr"], ["lqr", "pd"]),
    ],
)
def test_study_jobs_outside_their_range_are_refused_naming_the_field(schema, body, field, inside, outside):
    assert getattr(accepted(schema, body | {field: inside}), field) == inside
    assert refused(schema, body | {field: outside}) == [(field,)]


@pytest.mark.parametrize("kind", JOB_KINDS)
def test_unknown_fields_are_refused(kind):
    assert refused(JobCreate, BODIES[kind] | {"priority": 1}) == [(kind, "priority")]


def test_a_study_of_a_schedule_needs_its_controls():
    assert refused(JobCreate, {"kind": "basin"}) == [("basin", "controls")]
    assert refused(JobCreate, {"kind": "gaits"}) == [("gaits", "controls")]
    assert accepted(JobCreate, BASIN | {"guess": START}).guess.xdot == START["xdot"]


JOB = {
    "id": 3,
    "experiment_id": None,
    "kind": "mjtf",
    "state": "cancelled",
    "total": 16,
    "completed": 5,
    "progress": 5 / 16,
    "error": None,
    "spec": {"version": 1, "kind": "mjtf", "zeta0s": [0.9]},
    "created_at": datetime.datetime(2026, 12, 1, tzinfo=datetime.UTC),
    "started_at": datetime.datetime(2026, 12, 1, 0, 1, tzinfo=datetime.UTC),
    "finished_at": None,
}


def test_a_job_reads_back_in_one_of_its_states():
    assert [state.value for state in JobState] == ["queued", "running", "cancelling", "cancelled", "done", "failed"]
    job = JobOut.model_validate(JOB)
    assert job.state is JobState.CANCELLED
    assert refused(JobOut, JOB | {"state": "paused"}) == [("state",)]


def test_partial_results_list_the_levels_with_trials_and_those_without():
    results = JobResults.model_validate(
        {
            "job": JOB,
            "partial": True,
            "levels": [{"zeta0": 0.9, "trials": 5, "mean": 12.0, "std": 3.0, "outcomes": {"slip": 5}}],
            "missing_zeta0s": [0.92],
        }
    )
    assert results.result is None and results.levels[0].outcomes == {"slip": 5}
    assert JobResults.model_validate_json(results.model_dump_json()) == results


def test_an_mfpt_job_at_its_largest_grid_without_drift_is_within_the_budget():
    # Its worst case (both grids at the pair limit, the finest rule) is bounded by MFPT_MAX_PAIRS,
    # not by the grid: the chain refuses more pairs when it meets them.
    job = accepted(MfptJobCreate, MFPT | {"grid": 60, "pitch_spacing": 0.25, "noise": {"pitch_drift_deg": 0.0}})
    jumps, formula = worst_case_jumps(job)
    assert jumps <= WORK_BUDGET_JUMPS and "pairs" in formula


@pytest.mark.parametrize(
    ("change", "where", "says"),
    [
        ({"grid": 61}, ("grid",), "less than or equal to 60"),
        ({"grid": 3}, ("grid",), "greater than or equal to 4"),
        ({"pitch_spacing": 0.1}, ("pitch_spacing",), "greater than or equal to 0.25"),
        ({"zeta0": 1.0}, ("zeta0",), "less than 1"),
        ({"noise": {"asymmetry_psi0_deg": 0.5}}, ("noise",), "asymmetry_psi0_deg must be 0 for the MFPT chain"),
        ({"start": {"xdot": 0.5, "ydot": 0.0}}, ("start", "xdot"), "less than 0"),
    ],
)
def test_a_bad_mfpt_job_is_refused_naming_the_field(change, where, says):
    assert refused(MfptJobCreate, MFPT | change) == [where]
    assert says in refusal_messages(MfptJobCreate, MFPT | change)


def test_a_viability_job_at_its_largest_grid_is_within_the_budget_and_its_defaults_are_sim_cores():
    from sim_core.viability.grid import DEFAULT_PSI0_DEG, DEFAULT_ZETA0

    job = accepted(ViabilityJobCreate, VIABILITY | {"states": 120, "actions": 40})
    assert worst_case_jumps(job) == (120**2 * 40**2, "states² x actions²")
    assert worst_case_jumps(job)[0] <= WORK_BUDGET_JUMPS
    default = accepted(ViabilityJobCreate, VIABILITY)
    assert (default.psi0_low_deg, default.psi0_high_deg) == DEFAULT_PSI0_DEG
    assert (default.zeta0_low, default.zeta0_high) == DEFAULT_ZETA0


@pytest.mark.parametrize(
    ("change", "where", "says"),
    [
        ({"states": 121}, ("states",), "less than or equal to 120"),
        ({"actions": 1}, ("actions",), "greater than or equal to 2"),
        ({"zeta0_low": 0.01}, ("zeta0_low",), "greater than or equal to 0.05"),
        ({"psi0_high_deg": 90}, ("psi0_high_deg",), "less than or equal to 89"),
        ({"psi0_low_deg": 50, "psi0_high_deg": 40}, (), "psi0_low_deg must be below psi0_high_deg"),
        ({"zeta0_low": 0.9, "zeta0_high": 0.8}, (), "zeta0_low must be below zeta0_high"),
    ],
)
def test_a_bad_viability_job_is_refused_naming_the_field(change, where, says):
    assert refused(ViabilityJobCreate, VIABILITY | change) == [where]
    assert says in refusal_messages(ViabilityJobCreate, VIABILITY | change)


@pytest.mark.parametrize("kind", KINDS, ids=lambda kind: kind.name)
def test_each_registered_kind_names_itself_in_its_request_and_its_spec(kind):
    assert kind.request.model_fields["kind"].annotation == Literal[kind.name]
    assert next(field.default for field in dataclasses.fields(kind.spec) if field.name == "kind") == kind.name
    assert JOB_KINDS[kind.name] is kind.request and job_kind(kind.name) is kind
    with pytest.raises(UnreadableSpec, match="unknown job kind"):
        job_kind("no-such-kind")
