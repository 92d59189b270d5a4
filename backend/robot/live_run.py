"""A live run on the robot: its control loop, the one thread that owns the run's data.

The loop sets the legs, arms and starts the robot, then watches the tracker: each touchdown it
detects is recorded and, closed loop, goes through the run's law (a height controller,
:mod:`backend.robot.live_law`, or a plan's foot placement, :mod:`backend.robot.plan_law`) to the
leg of the touchdown after next — the one the robot positions during the coming stance. It ends
when its jumps or time are used up, when stopped, when its law ends it (a plan's goal or a missed
foothold), or when anything goes wrong (e-stop, a fall, a restart of the robot, a lost link; closed
loop, the tracker going blind: :mod:`backend.robot.tracker_watch`), each named
(:mod:`backend.robot.run_endings`); whatever ended it, it then disarms the robot, confirmed by
telemetry (:meth:`RobotLink.make_safe`). An open loop goes on through tracker gaps, each recorded.

Only the loop's thread writes the run's records. Everyone else sees them two ways, sharing nothing
mutable: :attr:`LiveRun.snapshot`, an immutable :class:`RunSnapshot` replaced whole after every
change (the panel, the live 3D view), and :attr:`LiveRun.journal`, a queue of :class:`Record` s —
each appended record, once, in order — that the journal writer drains
(:mod:`backend.services.robot_journal`)."""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from backend.robot.link import LinkError, LinkState, RobotLink
from backend.robot.live_law import LiveLaw, pitch_at
from backend.robot.messages import Leg
from backend.robot.run_endings import CLEAN_ENDINGS, LINK_LOST, RunEnds, end_safely, fault_names, robot_ending
from backend.robot.run_snapshot import RECENT_COMMANDS, Record, RunSnapshot
from backend.robot.touchdown import PITCH_LOOKBACK, SideAt, Touchdown, scan_touchdowns
from backend.robot.tracker import PoseHistory, pose_arrays
from backend.robot.tracker_watch import TRACKER_TIMEOUT_MS, TrackerWatch, frames_heard
from experiments.manifest import json_safe
from sim_core.model.controls import LegControl
from sim_core.model.errors import ParameterError
from sim_core.model.walls import wall_of

if TYPE_CHECKING:
    from backend.robot.plan_law import PlanLaw

POLL = 0.005  # [s] how often the loop looks at new poses

__all__ = ["CLEAN_ENDINGS", "LiveRun", "Record", "RunSnapshot", "end_safely", "execute", "telemetry_dict"]


@dataclass
class LiveRun:
    """A run's records, written by its control loop's thread only (:func:`execute`); other
    threads read :attr:`snapshot`, drain :attr:`journal`, or ask it to :meth:`stop`."""

    jumps: int  # touchdowns to record before it ends
    max_seconds: float  # [s] from the start, at most
    target_m: float | None = None  # closed loop: the height to hold [m]
    run_id: int | None = None
    started: float = field(default_factory=time.time)
    first_pose: int = 0  # the tracker's index of the run's first frame
    started_by: str | None = None  # who started it (the operator's name, or the client's address)
    tracker_timeout: float = TRACKER_TIMEOUT_MS / 1000.0  # [s] closed loop: the longest without a pose
    touchdowns: list[Touchdown] = field(default_factory=list)
    touchdown_controls: list[LegControl] = field(default_factory=list)
    commanded: dict[Leg, LegControl] = field(default_factory=dict)
    commands: list[dict] = field(default_factory=list)
    telemetry: list[dict] = field(default_factory=list)
    tracker_gaps: list[dict] = field(default_factory=list)
    robot_faults: tuple[str, ...] = ()
    world_id: int | None = None  # the stored world it climbs (None: the parallel walls)
    plan_job_id: int | None = None  # the plan job it follows (None: none)
    end_reason: str | None = None
    disarm: str | None = None
    journal: queue.SimpleQueue[Record] = field(default_factory=queue.SimpleQueue)
    done: threading.Event = field(default_factory=threading.Event)
    snapshot: RunSnapshot = field(init=False)
    _stop_requests: queue.SimpleQueue[str] = field(default_factory=queue.SimpleQueue)

    def __post_init__(self) -> None:
        self.snapshot = RunSnapshot(self.run_id, self.started, self.jumps, self.max_seconds, self.target_m,
                                    started_by=self.started_by, first_pose=self.first_pose,
                                    world_id=self.world_id, plan_job_id=self.plan_job_id)  # fmt: skip

    def stop(self, reason: str = "stopped") -> None:
        """Any thread: ask the loop to end; it sends nothing more once it has seen this (the first
        reason asked is the run's end reason)."""
        self._stop_requests.put(reason)

    # The loop's thread only -------------------------------------------------------------------
    def stop_reason(self) -> str | None:
        try:
            return self._stop_requests.get_nowait()
        except queue.Empty:
            return None

    def record(self, kind: str, value, into: list) -> None:
        into.append(value[0] if kind == "touchdown" else value)
        self.journal.put(Record(kind, value))

    def publish(self, **changes) -> None:
        """A new snapshot of the run (the loop's thread only): readers never see a half-made one."""
        self.snapshot = replace(
            self.snapshot,
            touchdowns=tuple(self.touchdowns),
            touchdown_controls=tuple(self.touchdown_controls),
            commanded=tuple(self.commanded.items()),
            commands=len(self.commands),
            recent_commands=tuple(json_safe(self.commands[-RECENT_COMMANDS:])),
            end_reason=self.end_reason,
            disarm=self.disarm,
            tracker_gaps=tuple(self.tracker_gaps),
            robot_faults=self.robot_faults,
            **changes,
        )


def execute(
    run: LiveRun,
    link: RobotLink,
    tracker: PoseHistory,
    robot,
    legs: list[LegControl],
    controller: LiveLaw | PlanLaw | None,
    on_end: Callable[[LiveRun], None],
    side_at: SideAt | None = None,
) -> None:
    """The run's control loop, on its own thread, to the end. Then the robot is made safe,
    ``on_end(run)`` stores the run, and only then the snapshot turns inactive and ``run.done`` is
    set, whatever happened. ``controller`` is the law closed at each touchdown (this thread
    owns it from here; it may end the run: :class:`RunEnds`), or None for open loop; ``robot``
    the physical parameters (touchdown detection, units); ``side_at`` a world's sides (None:
    parallel walls)."""
    commanded = run.commanded
    commanded.update({Leg.LEFT: legs[0], Leg.RIGHT: legs[1]})
    seen_poses = run.first_pose
    scan_from = run.first_pose + 1  # the tracker's index of the first pose not yet scanned for touchdowns

    def send(leg: Leg, control: LegControl, why: str, **law) -> None:
        link.set_leg(leg, control.psi0_deg, control.zeta0)
        commanded[leg] = control
        run.record("command", {"time": time.time(), "tracker_time": tracker.newest_time(run.first_pose),
                               "leg": leg.name.lower(), "psi0_deg": control.psi0_deg, "zeta0": control.zeta0,
                               "why": why, **law}, run.commands)  # fmt: skip
        run.publish()

    def leg_for(k: int) -> LegControl:
        # Detected touchdown k is the climb's touchdown k + 1: even climb touchdowns are the left leg's.
        controls = run.touchdown_controls
        return controls[k] if k < len(controls) else commanded[Leg.of(wall_of(k + 1))]

    try:
        send(Leg.LEFT, legs[0], "start")
        send(Leg.RIGHT, legs[1], "start")
        if link.state == LinkState.DISARMED:
            link.arm()
        restarts = link.restarts  # a restart of the robot from here on ends the run, named
        link.start()
        deadline = time.monotonic() + run.max_seconds
        watch = TrackerWatch(run.tracker_timeout, time.monotonic(), frames_heard(tracker))
        while run.end_reason is None:
            _record_telemetry(run, link, tracker)  # first: a fall's telemetry is the run's record of it
            run.end_reason = _ending(run, link, restarts, deadline)
            gap = watch.look(time.monotonic(), tracker.arrived(), frames_heard(tracker), tracker.waiting())
            _record_gaps(run, watch)
            if run.end_reason is None and gap is not None and controller is not None:
                run.end_reason = gap.reason(watch.bound_s)  # a closed loop never runs blind
            if run.end_reason is not None:
                break
            if tracker.count() == seen_poses:
                time.sleep(POLL)  # nothing new to analyse
                continue
            seen_poses = tracker.count()
            # Only the poses since the last scan (and the few looked back to): a new pose costs
            # the same at the thousandth jump as at the first, and the link's thread keeps its time.
            first, poses = tracker.numbered_from(max(run.first_pose, scan_from - 1 - PITCH_LOOKBACK))
            if scan_from - first < len(poses):
                arrays = pose_arrays(poses)
                scan = scan_touchdowns(arrays["time"], arrays["x"], arrays["y"], robot, leg_for, arrays["pitch"],
                                       start=scan_from - first, first_index=len(run.touchdowns),
                                       side_at=side_at)  # fmt: skip
                scan_from = first + scan.resume
                run.touchdown_controls.extend(leg_for(touchdown.index) for touchdown in scan.touchdowns)
                for touchdown in scan.touchdowns:
                    run.record("touchdown", (touchdown, run.touchdown_controls[touchdown.index]), run.touchdowns)
                    run.publish()
                    if controller is not None:
                        leg = Leg.of(wall_of(touchdown.index + 2))  # the next touchdown's (climb numbering)
                        pitch = pitch_at(arrays["time"], arrays["pitch"], touchdown.time)
                        try:
                            control, law = controller.command(touchdown, pitch, commanded[leg].psi0)
                        except RunEnds as ending:  # the plan's goal, or a foot off its plan
                            run.end_reason = str(ending)
                            break
                        send(leg, control, f"{controller.name} after touchdown {touchdown.index}", **law)
                if run.end_reason is None and len(run.touchdowns) >= run.jumps:
                    run.end_reason = "jumps done"
            time.sleep(POLL)
        _record_gaps(run, watch, ending=True)
    except (LinkError, ParameterError) as error:
        lost = link.state == LinkState.DISCONNECTED
        run.end_reason = run.end_reason or (f"{LINK_LOST}: {error}" if lost else f"error: {error}")
    finally:
        run.end_reason = run.end_reason or "error: the control loop failed"
        _record_telemetry(run, link, tracker)
        run.robot_faults = tuple(fault_names(run.telemetry[-1]["faults"])) if run.telemetry else ()
        run.disarm = end_safely(link)  # whatever ended it, and whatever the link believes
        run.publish()
        try:
            on_end(run)
        finally:
            run.publish(active=False)  # inactive once stored: a reader that saw it end finds it stored
            run.done.set()


def _ending(run: LiveRun, link: RobotLink, restarts: int, deadline: float) -> str | None:
    """Why the run must end now, or None. ``restarts``: the link's count of the robot's restarts
    when the run started it."""
    asked = run.stop_reason()
    if asked is not None:
        return asked
    if link.state != LinkState.RUNNING:
        faults = link.telemetry.faults if link.telemetry is not None else 0
        restart = link.last_restart if link.restarts > restarts else None
        return robot_ending(link.state, faults, restart, len(run.touchdowns))
    if time.monotonic() > deadline:
        return "time limit"
    return None


def _record_telemetry(run: LiveRun, link: RobotLink, tracker: PoseHistory) -> None:
    """The robot's latest telemetry, if it is new, into the run's record."""
    telemetry = link.telemetry
    if telemetry is not None and (not run.telemetry or run.telemetry[-1]["seq"] != telemetry.seq):
        stamps = {"time": time.time(), "tracker_time": tracker.newest_time(run.first_pose)}
        run.record("telemetry", stamps | telemetry_dict(telemetry), run.telemetry)


def _record_gaps(run: LiveRun, watch: TrackerWatch, *, ending: bool = False) -> None:
    """Tracker gaps past the bound that have ended (``ending``: the one going on too) into the record."""
    now = time.monotonic()
    gaps = watch.closed(now) if ending else watch.gaps
    for gap in gaps[len(run.tracker_gaps) :]:
        run.record("tracker_gap", gap.to_record(now, time.time()), run.tracker_gaps)
        run.publish()


def telemetry_dict(telemetry) -> dict:
    """A TELEMETRY message as the API and the stored run show it."""
    return {"seq": telemetry.seq, "state": telemetry.state.name.lower(), "psi_servo_deg": list(telemetry.psi_servo_deg),
            "zeta_servo": list(telemetry.zeta_servo), "battery_mv": telemetry.battery_mv,
            "faults": telemetry.faults}  # fmt: skip
