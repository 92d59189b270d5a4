"""A live run's journal: written while the run runs, and a failed write loses nothing."""

import time

from sqlalchemy import func, select
from sqlalchemy.exc import OperationalError

from backend.repositories import runs as run_store
from backend.robot.link import Transition
from backend.robot.live_run import LiveRun
from backend.robot.touchdown import Touchdown
from backend.robot.tracker import Calibration, Pose, UdpPoseSource
from backend.schemas import LegIn, RobotRunCreate
from backend.services.robot_journal import JournalWriter
from backend.services.robot_records import open_robot_run
from backend.store.models import RunJournal
from sim_core import get_preset
from sim_core.model.controls import LegControl
from sim_core.model.walls import Wall

LEGS = [LegIn(psi0_deg=30.0, zeta0=0.87), LegIn(psi0_deg=30.0, zeta0=0.9)]
WAIT_S = 30.0  # [s] an upper bound, not a timing assertion


def _wait_for(predicate, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not predicate():
        assert time.monotonic() < deadline, f"{what} within {WAIT_S:g} s"
        time.sleep(0.02)


def test_a_live_run_is_journaled_while_it_runs(connected, session):
    run_id = connected.start_run(RobotRunCreate(controls=LEGS, jumps=1000)).run_id
    _wait_for(lambda: len(connected.run_snapshot().touchdowns) >= 3, "three touchdowns")

    def journaled_touchdowns() -> int:
        entries = session.scalars(select(RunJournal.data).where(RunJournal.run_id == run_id)).all()
        return sum(len(data["touchdowns"]) for data in entries)

    _wait_for(lambda: journaled_touchdowns() >= 3, "the touchdowns in the journal")
    session.expire_all()
    stored = run_store.get_run(session, run_id)
    assert stored.status == "running" and stored.duration_s > 0
    connected.stop_run()
    session.expire_all()
    assert run_store.get_run(session, run_id).status == "done"
    assert session.scalar(select(func.count()).select_from(RunJournal)) == 0, "folded into the run at its end"


class _Link:
    def __init__(self):
        self.transitions: list[Transition] = []


class _FlakyStore:
    """The session factory, failing its first ``failures`` uses as a locked database does."""

    def __init__(self, sessions, failures: int):
        self.sessions, self.failures = sessions, failures

    def __call__(self):
        if self.failures:
            self.failures -= 1
            raise OperationalError("INSERT", {}, Exception("database is locked"))
        return self.sessions()


def test_a_failed_journal_write_loses_nothing(sessions, session):
    robot = get_preset("paper")
    with sessions() as opening:
        run_id = open_robot_run(opening, RobotRunCreate(controls=LEGS), robot, Calibration())
    tracker, run = UdpPoseSource(), LiveRun(jumps=20, max_seconds=60.0, run_id=run_id)
    store = _FlakyStore(sessions, failures=2)
    writer = JournalWriter(store, run, tracker, _Link(), robot, period=3600.0)  # entries by hand only
    for k in range(3):
        tracker.add(Pose(0.01 * k, 0.0, 0.1 * k, 0.0))
        touchdown = Touchdown(k, 0.01 * k, Wall.RIGHT if k % 2 == 0 else Wall.LEFT, (-0.9, 0.1), 0.1 * k, 0.1 * k, 8)
        run.record("touchdown", (touchdown, LegControl.from_degrees(30.0, 0.9)), run.touchdowns)
        writer._append(writer._collect())
    assert (writer.failures, writer.entries) == (2, 3), "the third write carried the first two"
    run.end_reason, run.disarm = "stopped", "disarmed"
    writer.start().finish(run)
    tracker.close()
    stored = run_store.get_run(session, run_id)
    assert [td["index"] for td in stored.results["touchdowns"]] == [0, 1, 2]
    assert stored.results["tracker"]["frames"] == 3 and stored.status == "done"


def test_a_runs_tracker_figures_are_its_own_not_the_connections(sessions, session):
    robot = get_preset("paper")
    tracker = UdpPoseSource()
    for number in (1, 2, 5, 6):  # before the run: 2 frames lost on this connection
        tracker.stats.frame(number)
    with sessions() as opening:
        run_id = open_robot_run(opening, RobotRunCreate(controls=LEGS), robot, Calibration())
    run = LiveRun(jumps=20, max_seconds=60.0, run_id=run_id)
    writer = JournalWriter(sessions, run, tracker, _Link(), robot, period=3600.0)
    for number in (7, 8, 10, 11, 12):  # during it: frame 9 lost
        tracker.stats.frame(number)
    tracker.stats.malformed += 1
    run.end_reason, run.disarm = "stopped", "disarmed"
    writer.start().finish(run)
    tracker.close()
    figures = run_store.get_run(session, run_id).results["tracker"]
    assert (figures["received"], figures["dropped"], figures["malformed"], figures["restarts"]) == (5, 1, 1, 0)
    assert figures["loss"] == 1 / 6 and (figures["protocol"], figures["version"]) == ("pkt1", "1")
    assert figures["address"] == list(tracker.address) and tracker.stats.dropped == 3, "the connection's own"
