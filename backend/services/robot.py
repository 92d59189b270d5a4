"""Live runs on the robot: the service's one link, its tracker, and the run in progress.

The link belongs to :class:`backend.robot.supervisor.LinkSupervisor`: connecting, disconnecting
and shutting down are requests to it, and it alone reconnects a dropped link. A live run is its
control loop's (:mod:`backend.robot.live_run`): the service starts it, asks it to stop, and reads
its immutable snapshots; its journal writer (:mod:`backend.services.robot_journal`) stores it
while it runs, and :mod:`backend.services.robot_records` folds it when it ends, or at the next
start if the service died first. The e-stop waits for none of this: :meth:`RobotService.estop_now`
runs it on the service's own e-stop thread, under no lock, bounded, and answers if it was acknowledged.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
import time
from functools import partial
from pathlib import Path

from backend.robot.latch import EstopLatch
from backend.robot.limits import ServoLimits
from backend.robot.link import LinkError, LinkState, RobotLink
from backend.robot.live_law import LiveLaw, live_law_for
from backend.robot.live_run import LiveRun, RunSnapshot, execute, telemetry_dict
from backend.robot.still_heap import on_a_still_heap
from backend.robot.supervisor import LinkSupervisor
from backend.schemas import RobotConnect, RobotRunCreate
from backend.services.presets import resolve_model
from backend.services.robot_estop import LATCH_SAVE_WAIT, latch_status, press
from backend.services.robot_journal import JournalWriter
from backend.services.robot_plans import run_world
from backend.services.robot_records import open_robot_run, recover_interrupted
from backend.services.robot_tracker import PoseSource, TrackerSlot
from experiments.manifest import json_safe
from sim_core.model.controls import LegControl
from sim_core.model.presets import get_preset

ESTOP_ANSWER = 0.17  # [s] the longest an e-stop waits for the robot (the link gives up at 0.15 s)
ANSWER_WAIT = ESTOP_ANSWER + LATCH_SAVE_WAIT  # [s] the longest a press waits: the robot, then the latch file
STOP_WAIT = 10.0  # [s] the longest a stop or a disconnect waits for the run to end and be stored


class RobotUnavailable(RuntimeError):
    """The robot is not connected, or busy with another run."""


class RobotService:
    """``latch_path``: where the e-stop latch is kept (the data directory's ``estop-latch.json`` in
    the service), so a restart finds it held; None keeps it in memory. ``radio_process``: each link's
    port in a radio process of its own, which keeps the heartbeats' time whatever this interpreter
    does (:mod:`backend.robot.radio_process`); False keeps it in a thread here (tests that reach into it)."""

    def __init__(self, sessions, robot=None, *, latch_path: Path | None = None, radio_process: bool = True):
        self.sessions = sessions
        self.radio_process = radio_process
        self.robot = robot or get_preset("paper")  # the robot's physical parameters
        self.supervisor = LinkSupervisor()  # the link's one owner (backend/robot/supervisor.py)
        self.latch = EstopLatch(latch_path)  # outlives every link: held until a RESET is acknowledged
        self._trackers = TrackerSlot()  # the tracker, replaced only once a new one is open
        self._run: LiveRun | None = None  # the latest live run (its loop's); read its snapshot
        self._lock = threading.Lock()  # connect, disconnect and starting a run, one at a time
        # The e-stop's own thread: not the request pool that compute can fill, and no lock that a
        # connect, a reconnect or a run holds. Presses while one is under way join it.
        self._estop_executor = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="robot-estop")
        self._estop_guard = threading.Lock()  # held only to read or replace _estop_pending
        self._estop_pending: concurrent.futures.Future | None = None

    # Connection: the supervisor alone opens, reconnects and closes the link ------------------
    @property
    def link(self) -> RobotLink | None:
        return self.supervisor.link

    @property
    def tracker(self) -> PoseSource | None:
        return self._trackers.tracker

    def run_snapshot(self) -> RunSnapshot | None:
        """The latest live run as it is now (immutable), or None before the first."""
        run = self._run
        return None if run is None else run.snapshot

    def recover(self) -> list[int]:
        """At start-up: live runs the service died during are stored as interrupted (their ids)."""
        return recover_interrupted(self.sessions, self.robot)

    def connect(self, body: RobotConnect) -> dict:
        """Open the link and tracker ``body`` names in place of the current ones. Refused while a
        live run goes on (409 naming it); one that fails leaves the working link and tracker as
        they were (the supervisor keeps a link on another port open until the new one answers)."""
        with self._lock:
            self._refuse_during_run("connect")
            limits = ServoLimits(tuple(body.psi0_limits_deg), tuple(body.zeta0_limits))
            tracker = self._trackers.open_beside(body)
            link = RobotLink(
                body.url, baud=body.baud, limits=limits, robot_address=int(body.robot_address, 16), latch=self.latch,
                radio_process=self.radio_process,
            )  # fmt: skip
            try:
                self.supervisor.connect(link)
            except LinkError:
                self._trackers.give_up(tracker)
                raise
            self._trackers.take(tracker, body)
        return self.status()

    def disconnect(self) -> dict:
        """Close the link (no more reconnects) and the tracker; refused while a live run goes on."""
        with self._lock:
            self._refuse_during_run("disconnect")
            self._disconnect()
        return self.status()

    def close(self) -> None:
        """Service shutdown: end a live run, close the link, end its supervisor, let the e-stop thread go."""
        with self._lock:
            run = self._run
            if run is not None and not run.done.is_set():
                run.stop("service shutdown")
                run.done.wait(STOP_WAIT)
            self._disconnect()
        self.supervisor.close()
        self._estop_executor.shutdown(wait=False)
        self.latch.flush()  # the latch as it is now is what the next start reads

    def _disconnect(self) -> None:
        """Close the link (no more reconnects) and the tracker."""
        self.supervisor.disconnect()
        self._trackers.close()

    def _refuse_during_run(self, what: str) -> None:
        """One operator per run: a link change while a live run goes on is a 409 naming the run (the
        e-stop, a disarm and stopping the run stay allowed)."""
        run = self.run_snapshot()
        if run is not None and run.active:
            who = f" by {run.started_by}" if run.started_by else ""
            raise RobotUnavailable(f"live run {run.run_id} (started{who}) is in progress: stop it before you {what}")

    def status(self) -> dict:
        """The robot as it is now, from immutable parts only (cheap: the live view sends it 20 times
        a second): link state, counters and telemetry, the e-stop latch, tracker and run."""
        link, tracker, run = self.link, self.tracker, self.run_snapshot()
        pose = tracker.latest() if tracker is not None else None
        return json_safe(
            {
                "state": LinkState.DISCONNECTED.value if link is None else link.state.value,
                "url": None if link is None else link.url,
                "robot_address": None if link is None else f"0x{link.robot_address:016X}",
                "counters": None if link is None else {**link.counters(), "reconnects": self.supervisor.reconnects},
                "estop": latch_status(self.latch, link),
                "last_delivery_failure": None if link is None else link.last_delivery_failure,
                "telemetry": None if link is None or link.telemetry is None else telemetry_dict(link.telemetry),
                "tracker": None
                if tracker is None
                else {
                    "address": list(tracker.address),
                    "received": tracker.stats.received,
                    "dropped": tracker.stats.dropped,
                    "malformed": tracker.stats.malformed,
                    "ignored": tracker.stats.ignored,
                    "restarts": tracker.stats.restarts,
                    "loss": tracker.stats.loss,
                    "protocol": tracker.protocol,
                    "version": tracker.version,
                    "error": tracker.error,
                    "latest": None if pose is None else vars(pose),
                    "last_pose_age_ms": _age_ms(tracker.arrived()),
                },
                "run": None if run is None else run.to_status(),
                "transitions": [] if link is None else [t.to_dict() for t in link.transitions[-20:]],
            }
        )

    def live(self) -> dict:
        """What the live view shows, cheaply: status plus the run's last few touchdowns."""
        status = self.status()
        run = self.run_snapshot()
        recent = [] if run is None else run.touchdowns[-5:]
        status["recent_touchdowns"] = json_safe(
            [{"index": td.index, "time": td.time, "wall": td.wall, "body_height": td.body_height} for td in recent]
        )
        return status

    # Commands --------------------------------------------------------------------------------
    def _connected(self) -> RobotLink:
        if self.link is None or self.link.state == LinkState.DISCONNECTED:
            raise RobotUnavailable("the robot is not connected")
        return self.link

    def arm(self) -> dict:
        self._refuse_during_run("arm")
        self._connected().arm()
        return self.status()

    def disarm(self) -> dict:
        self._connected().disarm()
        return self.status()

    def reset(self, by: str | None = None) -> dict:  # by: who asked (the latch keeps it)
        self._refuse_during_run("reset")
        self._connected().reset()
        if by is not None:
            self.latch.reset_by(by)
        return self.status()

    def estop(self, by: str | None = None) -> dict:
        """Emergency stop at any moment, bounded, connected or not (:func:`robot_estop.press`): ends
        a live run (still stored) whether or not the robot acknowledges, and latches. Answers
        ``acknowledged`` and ``latency_ms``; not acknowledged, a ``reason`` — the robot's watchdog
        then disarms it, as the link has stopped its heartbeats. Takes no lock: it must not wait
        for anything that moves."""
        return {**press(self.latch, self.link, self._run, by), **self.status()}

    async def estop_now(self, by: str | None = None) -> dict:
        """:meth:`estop` on the service's e-stop thread, for an ``async`` route: answers within
        ANSWER_WAIT whatever the link, the request pool or the locks are doing."""
        with self._estop_guard:
            if self._estop_pending is None or self._estop_pending.done():
                self._estop_pending = self._estop_executor.submit(self.estop, by)
            pending = self._estop_pending
        waiting = asyncio.wrap_future(pending)
        done, _ = await asyncio.wait({waiting}, timeout=ANSWER_WAIT)  # wait() never cancels it
        if done and waiting.exception() is None:
            return waiting.result()
        if done:  # a bug, not a fault of the line: still an answer, never a 500 for an e-stop
            reason = f"the e-stop failed: {waiting.exception()!r}"
        else:
            reason = f"the e-stop did not finish within {ANSWER_WAIT * 1000:.0f} ms (still trying)"
        return {"acknowledged": False, "latency_ms": ANSWER_WAIT * 1000.0, "reason": reason, **self.status()}

    # Live runs -------------------------------------------------------------------------------
    def start_run(self, body: RobotRunCreate, started_by: str | None = None, person: str | None = None) -> RunSnapshot:
        """Store the run, start its loop and journal. ``started_by``: as panels are told; ``person``: its creator."""
        link = self._connected()
        with self._lock:
            self._refuse_during_run("start another")
            with self.sessions() as session:  # the world climbed and the plan followed, if any (robot_plans.py)
                where = run_world(session, body, self.robot, link.limits)
            legs = where.legs or [LegControl.from_degrees(leg.psi0_deg, leg.zeta0) for leg in body.controls]
            for leg in legs:
                link.limits.check(leg.psi0_deg, leg.zeta0)  # a clear 422 before anything moves
            # Designed (and compiled) first: an e-stop pressed meanwhile is seen by the checks below.
            controller = where.law or self._law(body.closed_loop, legs, link.limits)
            if self.latch.held:
                raise RobotUnavailable(f"the e-stop latch holds ({self.latch.state.reason()}): reset before you start")
            if link.state not in (LinkState.DISARMED, LinkState.ARMED):
                raise RobotUnavailable(f"the robot is {link.state.value}; it must be disarmed or armed to start")
            tracker = self.tracker
            with self.sessions() as session:
                on = {"url": link.url, "robot_address": f"0x{link.robot_address:016X}"}
                run_id = open_robot_run(session, body, self.robot, tracker.calibration, started_by=started_by, link=on,
                                        person=person, legs=legs, world_id=where.world_id)  # fmt: skip
            target_m = None if body.closed_loop is None else body.closed_loop.target_m
            run = LiveRun(body.jumps, body.max_seconds, target_m, run_id=run_id, first_pose=tracker.count(),
                          started_by=started_by, tracker_timeout=body.tracker_timeout_ms / 1000.0,
                          world_id=where.world_id, plan_job_id=body.plan_job_id)  # fmt: skip
            journal = JournalWriter(self.sessions, run, tracker, link, self.robot).start()
            self._run = run
        loop = partial(execute, run, link, tracker, self.robot, legs, controller, journal.finish, where.side_at)
        threading.Thread(target=on_a_still_heap, args=(loop,), name="robot-live-run", daemon=True).start()
        return run.snapshot

    def wait_run(self, timeout: float) -> RunSnapshot | None:
        """Wait up to ``timeout`` [s] for the latest live run to end and be stored; its snapshot
        then (``active`` False if it ended), or None if there is none."""
        run = self._run
        if run is None:
            return None
        run.done.wait(timeout)
        return run.snapshot

    def _law(self, loop, legs: list[LegControl], limits) -> LiveLaw | None:
        """The closed loop's law (None: open loop), designed on its ``preset`` (a stored calibration:
        its fitted robot and leg offsets) or on the service's robot."""
        if loop is None:
            return None
        if loop.preset is None:
            return live_law_for(loop, self.robot, legs, limits)
        with self.sessions() as session:
            design = resolve_model(session, loop.preset, field="closed_loop.preset")
        return live_law_for(loop, design.robot, legs, limits, offsets=design.offsets)

    def stop_run(self) -> dict:
        """End the live run (its ending disarms) and the status after; with no live run, nothing to
        stop: the status as it is (stopping is always possible, and a second press is no error)."""
        run = self._run
        if run is None:
            return self.status()
        run.stop("stopped")
        run.done.wait(STOP_WAIT)
        return self.status()


def _age_ms(arrived: float) -> float | None:
    """How long ago [ms] a ``time.monotonic()`` arrival was; None if never."""
    return None if arrived == float("-inf") else (time.monotonic() - arrived) * 1000.0
