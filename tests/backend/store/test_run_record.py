"""A run as produced, before it is stored (backend/store/run_record.py): a frozen record with no
database imports, whose fields are the run row's columns (backend/repositories/runs.py adds it)."""

import dataclasses
import subprocess
import sys

import pytest

from backend.repositories import runs as run_store
from backend.store.models import Run
from backend.store.run_record import RunRecord

RECORD = RunRecord(
    kind="sim",
    status="done",
    model={"alpha": 77.6, "d_hat": 2.42, "c_zeta": 0.0, "c_psi": 0.0, "mu": None},
    controls=[[30.0, 0.87], [35.0, 0.9]],
    start_state=[-0.93, -0.17],
    jumps=4,
    jumps_completed=2,
    climb=1.25,
    results={"rises": [0.6, 0.65], "failure": {"code": "slip", "jump": 2}},
    code_version="abc123",
    failure_code="slip",
    duration_s=0.02,
    trajectory=b"\x78\x9c",
    tags=("b", "a", "b"),
)


def test_a_record_says_only_what_was_produced_and_defaults_the_rest():
    produced = ("kind", "status", "model", "controls", "start_state", "jumps", "jumps_completed", "climb",
                "results", "code_version")  # fmt: skip
    minimal = RunRecord(**{name: getattr(RECORD, name) for name in produced})
    assert (minimal.failure_code, minimal.duration_s, minimal.trajectory, minimal.tags) == (None, 0.0, None, ())
    with pytest.raises(TypeError, match="code_version"):
        RunRecord(**{name: getattr(RECORD, name) for name in produced[:-1]})


def test_a_record_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        RECORD.climb = 9.0  # type: ignore[misc]


def test_every_field_but_the_tags_is_a_column_of_the_run_row():
    """``add_run`` passes the record's fields to the row as they are: a field without a column of
    the same name would fail there, at the first run stored."""
    columns = set(Run.__table__.columns.keys())
    assert {field.name for field in dataclasses.fields(RunRecord)} - {"tags"} <= columns


def test_a_stored_record_reads_back_field_for_field(session):
    run = run_store.add_run(session, RECORD)
    session.commit()
    run_id = run.id
    session.expunge_all()
    stored = run_store.get_run(session, run_id)
    for field in dataclasses.fields(RunRecord):
        expected = getattr(RECORD, field.name)
        if field.name == "tags":
            assert stored.tags == ["a", "b"], "deduplicated and sorted"
        else:
            assert getattr(stored, field.name) == expected, field.name
    assert (stored.alpha, stored.psi0_deg, stored.zeta0) == (77.6, 30.0, 0.87), "filter columns: model, first leg"
    assert stored.has_trajectory


def test_the_record_loads_no_database_code():
    """The compute workers build records: they must not pay for importing SQLAlchemy."""
    code = "import sys, backend.store.run_record; print('sqlalchemy' in sys.modules)"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == "False"
