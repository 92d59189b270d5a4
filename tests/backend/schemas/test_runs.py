"""Runs' bodies (backend/schemas/runs.py): simulate-and-store requests bounded in jumps and path
samples, label-only edits, and stored runs read back whatever today's limits are."""

import datetime

import pytest

from backend.schemas.common import MAX_ID, MAX_JUMPS, MAX_PATH_SAMPLES
from backend.schemas.runs import RunCreate, RunDetail, RunKind, RunOut, RunStatus, RunTrajectory, RunUpdate
from tests.backend.schemas.refusals import LEG, START, accepted, refusal_messages, refused

RUN = {"controls": [LEG], "start": START}
STORED = {
    "id": 7,
    "experiment_id": None,
    "jumps": 20,
    "kind": "sim",
    "status": "done",
    "created_at": datetime.datetime(2026, 12, 1, tzinfo=datetime.UTC),
    "duration_s": 0.01,
    "code_version": "abc123",
    "model": {"alpha": 70.0},
    "controls": [[30.0, 0.9]],
    "start_state": [-0.93, -0.17],
    "jumps_completed": 20,
    "failure_code": None,
    "climb": 5.2,
    "tags": [],
    "notes": "",
    "has_trajectory": False,
}


def test_a_run_defaults_to_20_jumps_of_the_paper_model_without_a_path():
    run = accepted(RunCreate, RUN)
    assert (run.jumps, run.model.preset, run.trajectory_rate, run.fixed_point) == (20, "paper", None, False)
    assert (run.experiment_id, run.tags) == (None, [])


@pytest.mark.parametrize(
    ("field", "inside", "outside"),
    [
        ("jumps", 1, 0),
        ("jumps", MAX_JUMPS, MAX_JUMPS + 1),
        ("trajectory_rate", 1e-3, 0.0),
        ("experiment_id", MAX_ID, MAX_ID + 1),
        ("controls", [LEG] * 16, [LEG] * 17),
        ("controls", [LEG], []),
        ("tags", ["a"] * 32, ["a"] * 33),
    ],
)
def test_a_run_outside_its_range_is_refused_naming_the_field(field, inside, outside):
    assert accepted(RunCreate, RUN | {field: inside}).model_dump()[field] == inside
    assert refused(RunCreate, RUN | {field: outside}) == [(field,)]


def test_the_path_rate_is_at_most_1000_samples_per_time_unit():
    assert accepted(RunCreate, RUN | {"jumps": 1, "trajectory_rate": 1000.0}).trajectory_rate == 1000.0
    assert refused(RunCreate, RUN | {"jumps": 1, "trajectory_rate": 1000.5}) == [("trajectory_rate",)]


def test_a_stored_path_is_capped_at_rate_times_jumps():
    at_the_cap = RUN | {"jumps": 1000, "trajectory_rate": MAX_PATH_SAMPLES / 1000}
    assert accepted(RunCreate, at_the_cap).jumps == 1000
    over = at_the_cap | {"jumps": 1001}
    assert refused(RunCreate, over) == [("trajectory_rate",)], "the path's rate is what is refused"
    assert accepted(RunCreate, RUN | {"jumps": MAX_JUMPS}).trajectory_rate is None, "no path: no cap"


def test_a_path_too_long_to_keep_is_refused_in_the_askers_terms():
    """The panel's Save run once sent 60 samples per sqrt(l0/g) for 2,000 jumps and was told
    "trajectory_rate x jumps must be at most 100,000", a product nobody typed: the message says
    what the path would be, how many jumps fit at that rate, and the rate (or no path) that fits."""
    message = refusal_messages(RunCreate, RUN | {"jumps": 2000, "trajectory_rate": 60.0}).removeprefix("Value error, ")
    assert message.startswith("a path of 2,000 jumps at 60 samples per sqrt(l0/g) would be about 180,000 samples")
    assert "at this rate a path is kept for up to 1,666 jumps" in message, message
    assert "for 2,000 jumps, a rate of at most 50, or no trajectory_rate" in message, message
    assert "trajectory_rate x jumps" not in message
    assert accepted(RunCreate, RUN | {"jumps": 2000, "trajectory_rate": 50.0}).trajectory_rate == 50.0
    assert accepted(RunCreate, RUN | {"jumps": MAX_JUMPS, "trajectory_rate": 10.0}).jumps == MAX_JUMPS


def test_nested_errors_name_the_leg_the_start_and_the_model():
    body = RUN | {"controls": [LEG, LEG | {"psi0_deg": 0.0}], "start": START | {"xdot": 0.1}, "model": {"d_hat": 0}}
    assert sorted(refused(RunCreate, body)) == [("controls", 1, "psi0_deg"), ("model", "d_hat"), ("start", "xdot")]


def test_a_run_needs_controls_and_a_start_and_nothing_else():
    assert refused(RunCreate, {"start": START}) == [("controls",)]
    assert refused(RunCreate, {"controls": [LEG]}) == [("start",)]
    assert refused(RunCreate, RUN | {"climb": 9.0}) == [("climb",)]


def test_an_edit_changes_only_tags_and_notes():
    assert accepted(RunUpdate, {"tags": ["ok"]}).model_dump(exclude_none=True) == {"tags": ["ok"]}
    assert accepted(RunUpdate, {"notes": "n" * 100_000}).notes == "n" * 100_000
    assert refused(RunUpdate, {"notes": "n" * 100_001}) == [("notes",)]
    for recorded in ("jumps", "climb", "controls", "kind"):
        assert refused(RunUpdate, {recorded: 1}) == [(recorded,)], f"{recorded} is a record of what happened"


def test_kinds_and_statuses_are_the_strings_the_store_keeps():
    assert [kind.value for kind in RunKind] == ["sim", "robot", "replay"]
    assert [status.value for status in RunStatus] == ["done", "failed", "running", "interrupted"]
    out = RunOut.model_validate(STORED | {"kind": "replay", "status": "interrupted"})
    assert out.kind is RunKind.REPLAY and out.status is RunStatus.INTERRUPTED
    assert refused(RunOut, STORED | {"kind": "dream"}) == [("kind",)]


def test_a_stored_run_reads_back_beyond_todays_input_limits():
    older = STORED | {"jumps": 20 * MAX_JUMPS, "tags": ["two words"], "experiment_id": None}
    out = RunOut.model_validate(older)
    assert (out.jumps, out.tags) == (20 * MAX_JUMPS, ["two words"])
    detail = RunDetail.model_validate(older | {"results": {"rises": [0.1]}})
    assert detail.results == {"rises": [0.1]}
    assert RunDetail.model_validate_json(detail.model_dump_json()) == detail


def test_a_path_is_in_nondimensional_or_si_units():
    path = {"units": "SI", "column_units": {"time": "s", "x": "m"}, "columns": {"time": [0.0, 0.01], "x": [0.1, 0.2]}}
    assert RunTrajectory.model_validate(path).model_dump() == path
    assert refused(RunTrajectory, path | {"units": "imperial"}) == [("units",)]
