"""Robot runs in the store: opened running, folded from their journal, recovered as interrupted."""

import datetime

import pytest
from sqlalchemy import func, select

from backend import errors
from backend.repositories import runs as run_store
from backend.robot.touchdown import Touchdown
from backend.robot.tracker import Calibration
from backend.schemas import LegIn, RobotRunCreate
from backend.services.robot_records import INTERRUPTED, fold_journal, open_robot_run, recover_interrupted, replay_run
from backend.store.models import RunJournal
from backend.store.trajectory_blob import unpack_trajectory
from sim_core import get_preset
from sim_core.model.walls import Wall

REQUEST = RobotRunCreate(controls=[LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)], tags=["t"])


def _touchdown(k: int) -> dict:
    wall = Wall.RIGHT if k % 2 == 0 else Wall.LEFT
    return Touchdown(k, 0.3 * k, wall, (-0.9, 0.1 + 0.01 * k), 0.4 + 0.01 * k, 0.35 + 0.01 * k, 8).to_dict()


def _entry(run_id: int, first: int, frames: int, touchdowns: list[int], written_at) -> RunJournal:
    times = [0.01 * (first + i) for i in range(frames)]
    return RunJournal(
        run_id=run_id,
        written_at=written_at,
        data={
            "frames": {"time": times, "x": [0.0] * frames, "y": times, "pitch": [0.0] * frames},
            "touchdowns": [{"touchdown": _touchdown(k), "control": [30.0, 0.87 if k % 2 else 0.9]} for k in touchdowns],
            "commands": [{"why": "start"}] if first == 0 else [],
            "telemetry": [{"seq": first}],
            "transitions": [],
            "tracker": {"dropped": first, "loss": 0.0},
        },
    )


@pytest.fixture
def journaled(session):
    """A robot run opened and given two journal entries (50 frames, 3 touchdowns), never ended."""
    run_id = open_robot_run(session, REQUEST, get_preset("paper"), Calibration())
    created = run_store.get_run(session, run_id).created_at
    session.add_all([
        _entry(run_id, 0, 30, [0, 1], created + datetime.timedelta(seconds=0.5)),
        _entry(run_id, 30, 20, [2], created + datetime.timedelta(seconds=1.0)),
    ])  # fmt: skip
    session.commit()
    return run_id


def test_a_run_is_stored_running_from_its_start(session, journaled):
    run = run_store.get_run(session, journaled)
    assert (run.kind, run.status, run.tags, run.jumps, run.jumps_completed) == ("robot", "running", ["t"], 20, 0)
    assert run.results["end_reason"] is None and run.results["calibration"]["scale"] == 1.0
    with pytest.raises(errors.Conflict, match="still running"):
        replay_run(session, journaled)


def test_recovery_folds_the_journal_into_an_interrupted_run(sessions, session, journaled, make_run):
    done = make_run()
    assert recover_interrupted(sessions) == [journaled]
    session.expire_all()
    run = run_store.get_run(session, journaled)
    assert (run.status, run.results["end_reason"], run.jumps_completed) == ("interrupted", INTERRUPTED, 2)
    assert run.results["disarm"].startswith("not confirmed")
    assert [td["index"] for td in run.results["touchdowns"]] == [0, 1, 2]
    controls = run.results["touchdown_controls"]
    assert [zeta0 for _, zeta0 in controls] == [0.9, 0.87, 0.9] and [psi for psi, _ in controls] == pytest.approx(
        [30] * 3
    )
    assert run.results["commands"] == [{"why": "start"}] and len(run.results["telemetry"]) == 2
    assert run.results["tracker"] == {"frames": 50, "dropped": 30, "loss": 0.0}
    assert run.duration_s == pytest.approx(1.0) and run.start_state == [-0.9, 0.1]
    assert unpack_trajectory(run.trajectory)["time"].size == 50
    assert session.scalar(select(func.count()).select_from(RunJournal)) == 0, "the journal is folded away"
    assert run_store.get_run(session, done.id).status == "done", "finished runs are left alone"
    assert recover_interrupted(sessions) == [], "once"


def test_a_fold_without_entries_keeps_the_run(session):
    run_id = open_robot_run(session, REQUEST, get_preset("paper"), Calibration())
    run = fold_journal(session, run_id, status="failed", end_reason="error: no tracker", disarm="disarmed")
    assert (run.status, run.trajectory, run.results["touchdowns"], run.results["tracker"]["frames"]) == (
        "failed", None, [], 0)  # fmt: skip
