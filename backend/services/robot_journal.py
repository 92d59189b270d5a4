"""A live run's journal writer: what the run recorded reaches the store at least once a second.

One thread per live run, sharing nothing mutable with the control loop: every ``period`` it
drains the run's queue of :class:`~backend.robot.live_run.Record` s, takes the tracker frames
and link transitions that arrived since its last entry, and appends them as one
:class:`~backend.store.models.RunJournal` entry. A write that fails (the database locked, the disk
full) loses nothing: the entry is kept and written with the next one, and the failure is logged
once per kind. When the run ends, :meth:`JournalWriter.finish` writes the last entry and folds
the journal into the run (:func:`~backend.services.robot_records.fold_journal`).
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import asdict

from sqlalchemy.exc import SQLAlchemyError

from backend.repositories import robot_runs
from backend.repositories import runs as stored_runs
from backend.robot.link import RobotLink
from backend.robot.live_run import CLEAN_ENDINGS, LiveRun, Record
from backend.robot.tracker import UdpPoseSource
from backend.services.robot_records import FRAME_COLUMNS, fold_journal
from experiments.manifest import json_safe

log = logging.getLogger("parkourlab.robot")

JOURNAL_PERIOD = 0.5  # [s] between entries: a crash loses at most this much, plus one write


class JournalWriter:
    """Appends ``run``'s records, frames and transitions to the store every ``period`` [s]."""

    def __init__(self, sessions, run: LiveRun, tracker: UdpPoseSource, link: RobotLink, robot,
                 period: float = JOURNAL_PERIOD):  # fmt: skip
        self.sessions = sessions
        self.run = run
        self.tracker = tracker
        self.link = link
        self.robot = robot
        self.period = period
        self.entries = 0  # written so far
        self.failures = 0  # writes that failed (their data went out with a later entry)
        self._next_pose = run.first_pose
        self._tracker_at_start = tracker.stats.snapshot()  # the run's figures are the counts since
        self._transitions_seen = len(link.transitions)
        self._unwritten: list[dict] = []  # entries a failed write left, oldest first (this thread's)
        self._finished = threading.Event()
        self._thread = threading.Thread(target=self._serve, name=f"robot-journal-{run.run_id}", daemon=True)

    def start(self) -> JournalWriter:
        self._thread.start()
        return self

    def finish(self, run: LiveRun) -> None:
        """The run has ended (the control loop's ``on_end``): the last entry, then the fold."""
        self._finished.set()
        self._thread.join()
        self._append(self._collect())
        status = "done" if run.end_reason.split(":")[0] in CLEAN_ENDINGS else "failed"  # its family
        try:
            with self.sessions() as session:
                fold_journal(session, run.run_id, status=status, end_reason=run.end_reason,
                             disarm=run.disarm, robot=self.robot, faults=run.robot_faults)  # fmt: skip
        except SQLAlchemyError:
            # The entries are stored: the next start folds them as an interrupted run.
            log.exception("could not store the end of robot run %s; it is folded at the next start", run.run_id)

    # The writer's thread (and finish, after it has joined) -------------------------------------
    def _serve(self) -> None:
        while not self._finished.wait(self.period):
            self._append(self._collect())

    def _collect(self) -> dict:
        """What arrived since the previous entry, as the entry's JSON."""
        records: list[Record] = []
        while not self.run.journal.empty():
            records.append(self.run.journal.get_nowait())
        poses = self.tracker.poses_from(self._next_pose)
        self._next_pose += len(poses)
        transitions = self.link.transitions[self._transitions_seen :]
        self._transitions_seen += len(transitions)
        counts = self.tracker.stats.snapshot().since(self._tracker_at_start)
        return json_safe(
            {
                "frames": {name: [getattr(pose, name) for pose in poses] for name in FRAME_COLUMNS},
                "touchdowns": [_touchdown_entry(*r.value) for r in records if r.kind == "touchdown"],
                "commands": [r.value for r in records if r.kind == "command"],
                "telemetry": [r.value for r in records if r.kind == "telemetry"],
                "tracker_gaps": [r.value for r in records if r.kind == "tracker_gap"],
                "transitions": [transition.to_dict() for transition in transitions],
                "tracker": {
                    **asdict(counts),
                    "loss": counts.loss,
                    "protocol": self.tracker.protocol,
                    "version": self.tracker.version,  # NatNet's is known once the server answers
                    "address": list(self.tracker.address),
                },
            }
        )

    def _append(self, entry: dict) -> None:
        self._unwritten.append(entry)
        started = time.time()
        try:
            with self.sessions() as session:
                robot_runs.append_journal(session, self.run.run_id, self._unwritten)
                run = stored_runs.find(session, self.run.run_id)
                run.duration_s = started - self.run.started
                session.commit()
        except SQLAlchemyError as error:
            self.failures += 1
            if self.failures == 1:
                log.warning("robot run %s: a journal write failed (%s); retrying with the next", self.run.run_id, error)
            return
        self.entries += len(self._unwritten)
        self._unwritten = []


def _touchdown_entry(touchdown, control) -> dict:
    return {"touchdown": touchdown.to_dict(), "control": [control.psi0_deg, control.zeta0]}
