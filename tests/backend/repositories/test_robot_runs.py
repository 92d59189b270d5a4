"""Robot runs' journal SQL (backend/repositories/robot_runs.py) on a migrated SQLite file."""

from backend.repositories import robot_runs
from backend.store.models import Run


def _run(session, kind: str, status: str) -> int:
    run = Run(kind=kind, status=status, code_version="test", model={}, controls=[], start_state=[], jumps=1,
              alpha=1.0, psi0_deg=30.0, zeta0=0.9, jumps_completed=0, climb=0.0, results={})  # fmt: skip
    session.add(run)
    session.commit()
    return run.id


def test_a_journal_reads_back_in_order_and_is_deleted_per_run(session):
    first, second = _run(session, "robot", "running"), _run(session, "robot", "running")
    robot_runs.append_journal(session, first, [{"k": 1}, {"k": 2}])
    robot_runs.append_journal(session, second, [{"k": 9}])
    robot_runs.append_journal(session, first, [{"k": 3}])
    session.commit()
    assert [entry.data["k"] for entry in robot_runs.journal(session, first)] == [1, 2, 3]
    robot_runs.delete_journal(session, first)
    session.commit()
    assert robot_runs.journal(session, first) == []
    assert [entry.data["k"] for entry in robot_runs.journal(session, second)] == [9], "another run's entries stay"


def test_running_robot_runs_are_only_robot_runs_still_running(session):
    running = _run(session, "robot", "running")
    _run(session, "robot", "done")
    _run(session, "sim", "running")
    assert robot_runs.running_robot_run_ids(session) == [running]
