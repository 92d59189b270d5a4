"""Live runs on the robot: the service's one link, its tracker, and the run in progress.

A live run sets the legs, arms and starts the robot, and records everything: raw tracker
frames, the touchdowns detected in them, every command sent, telemetry and link transitions.
Closed loop, each detected touchdown's height goes through the simulator's PID
(:func:`sim_core.closed_loop.pid_step`) to the leg of the touchdown after next — the one the
robot positions during the coming stance. The run ends when its jumps or time are used up,
when stopped, or when anything goes wrong (e-stop, fall, lost link); whatever ended it, it then
disarms the robot, confirmed by telemetry (:meth:`RobotLink.make_safe`), and is stored as a run
of kind ``robot``, with the model's prediction for the same controls beside it.

The link itself belongs to :class:`backend.robot.supervisor.LinkSupervisor`: connecting,
disconnecting and shutting down are requests to it, and it alone reconnects a dropped link.
The e-stop does not wait for any of this: :meth:`RobotService.estop_now` runs it on the service's
own e-stop thread, under no lock, bounded, and answers whether the robot acknowledged it.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import math
import threading
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from backend.robot.limits import ServoLimits
from backend.robot.link import EstopResult, LinkError, LinkState, RobotLink
from backend.robot.messages import Leg
from backend.robot.supervisor import LinkSupervisor
from backend.robot.touchdown import Touchdown, detect_touchdowns, height_gains
from backend.robot.tracker import Calibration, UdpPoseSource
from backend.schemas import RobotConnect, RobotRunCreate
from backend.services.records import Conflict, NotFound
from backend.services.simulation import current_code_version, pack_trajectory, unpack_trajectory
from backend.store.models import Run, RunTag
from experiments.manifest import json_safe
from sim_core.controls import ControlSchedule, LegControl
from sim_core.errors import ParameterError
from sim_core.presets import get_preset
from sim_core.walls import wall_of

POLL = 0.005  # [s] how often a live run looks at new poses
ESTOP_ANSWER = 0.17  # [s] the longest an e-stop request waits for its answer (the link gives up at 0.15 s)


class RobotUnavailable(RuntimeError):
    """The robot is not connected, or busy with another run."""


@dataclass
class LiveRun:
    request: RobotRunCreate
    started: float = field(default_factory=time.time)
    touchdowns: list[Touchdown] = field(default_factory=list)
    commands: list[dict] = field(default_factory=list)
    telemetry: list[dict] = field(default_factory=list)
    # The controls each detected touchdown was made with, and what each leg is commanded now
    # (the 3D view's model ghost reads both).
    touchdown_controls: list[LegControl] = field(default_factory=list)
    commanded: dict[Leg, LegControl] = field(default_factory=dict)
    end_reason: str | None = None
    disarm: str | None = None  # how the run's ending left the robot: "disarmed", "estopped" or why unconfirmed
    stored_run_id: int | None = None
    stop_requested: threading.Event = field(default_factory=threading.Event)
    done: threading.Event = field(default_factory=threading.Event)


class RobotService:
    def __init__(self, sessions, robot=None):
        self.sessions = sessions
        self.robot = robot or get_preset("paper")  # the robot's physical parameters
        self.supervisor = LinkSupervisor()  # the link's one owner (backend/robot/supervisor.py)
        self.tracker: UdpPoseSource | None = None
        self.run: LiveRun | None = None
        self._lock = threading.Lock()
        # The e-stop's own thread: not the request pool that compute can fill, and no lock that a
        # connect, a reconnect or a run holds. Presses while one is under way join it.
        self._estop_executor = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="robot-estop")
        self._estop_guard = threading.Lock()  # held only to read or replace _estop_pending
        self._estop_pending: concurrent.futures.Future | None = None

    # Connection: the supervisor alone opens, reconnects and closes the link ------------------
    @property
    def link(self) -> RobotLink | None:
        return self.supervisor.link

    def connect(self, body: RobotConnect) -> dict:
        with self._lock:
            self._disconnect()
            limits = ServoLimits(tuple(body.psi0_limits_deg), tuple(body.zeta0_limits))
            calibration = Calibration(tuple(body.calibration_origin), body.calibration_angle, body.calibration_scale)
            self.tracker = UdpPoseSource(body.tracker_host, body.tracker_port, calibration=calibration)
            link = RobotLink(body.url, baud=body.baud, limits=limits, robot_address=int(body.robot_address, 16))
            try:
                self.supervisor.connect(link)
            except LinkError:
                self.tracker.close()
                self.tracker = None
                raise
        return self.status()

    def disconnect(self) -> dict:
        with self._lock:
            self._disconnect()
        return self.status()

    def close(self) -> None:
        """Service shutdown: disconnect, end the link's supervisor, and let the e-stop thread go."""
        self.disconnect()
        self.supervisor.close()
        self._estop_executor.shutdown(wait=False)

    def _disconnect(self) -> None:
        """End a live run, close the link (no more reconnects) and the tracker."""
        if self.run is not None and not self.run.done.is_set():
            self.run.stop_requested.set()
            self.run.done.wait(5)
        self.supervisor.disconnect()
        if self.tracker is not None:
            self.tracker.close()
            self.tracker = None

    def status(self) -> dict:
        link, tracker, run = self.link, self.tracker, self.run
        pose = tracker.latest() if tracker is not None else None
        return json_safe(
            {
                "state": LinkState.DISCONNECTED.value if link is None else link.state.value,
                "url": None if link is None else link.url,
                "robot_address": None if link is None else f"0x{link.robot_address:016X}",
                "counters": None if link is None else link.counters(),
                "telemetry": None if link is None or link.telemetry is None else _telemetry(link.telemetry),
                "tracker": None
                if tracker is None
                else {
                    "address": list(tracker.address),
                    "received": tracker.stats.received,
                    "dropped": tracker.stats.dropped,
                    "malformed": tracker.stats.malformed,
                    "loss": tracker.stats.loss,
                    "latest": None if pose is None else vars(pose),
                },
                "run": None
                if run is None
                else {
                    "active": not run.done.is_set(),
                    "touchdowns": len(run.touchdowns),
                    "end_reason": run.end_reason,
                    "disarm": run.disarm,
                    "stored_run_id": run.stored_run_id,
                },
                "transitions": [] if link is None else _transitions(link.transitions[-20:]),
            }
        )

    def live(self) -> dict:
        """What the live view shows, cheaply: status plus the run's last few touchdowns."""
        status = self.status()
        run = self.run
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
        self._connected().arm()
        return self.status()

    def disarm(self) -> dict:
        self._connected().disarm()
        return self.status()

    def reset(self) -> dict:
        self._connected().reset()
        return self.status()

    def estop(self) -> dict:
        """Emergency stop at any moment, bounded (the link gives up after ESTOP_TIMEOUT): ends a live
        run (still stored) whether or not the robot acknowledges. Answers ``acknowledged`` and
        ``latency_ms``; not acknowledged, a ``reason`` — the robot's watchdog then disarms it, as
        the link has stopped its heartbeats. Takes no lock: it must not wait for anything that moves."""
        link, run = self.link, self.run
        if run is not None and not run.done.is_set():
            run.end_reason = run.end_reason or "e-stop"
            run.stop_requested.set()  # before the e-stop: the control loop sends nothing more
        result = EstopResult(False, 0.0, "the robot is not connected") if link is None else link.estop()
        answer = {"acknowledged": result.acknowledged, "latency_ms": result.latency * 1000.0}
        if not result.acknowledged:
            answer["reason"] = result.reason
        return {**answer, **self.status()}

    async def estop_now(self) -> dict:
        """:meth:`estop` on the service's e-stop thread, for an ``async`` route: answers within
        ESTOP_ANSWER whatever the link, the request pool or the locks are doing."""
        with self._estop_guard:
            if self._estop_pending is None or self._estop_pending.done():
                self._estop_pending = self._estop_executor.submit(self.estop)
            pending = self._estop_pending
        waiting = asyncio.wrap_future(pending)
        done, _ = await asyncio.wait({waiting}, timeout=ESTOP_ANSWER)  # wait() never cancels it
        if done and waiting.exception() is None:
            return waiting.result()
        if done:  # a bug, not a fault of the line: still an answer, never a 500 for an e-stop
            reason = f"the e-stop failed: {waiting.exception()!r}"
        else:
            reason = f"the e-stop did not finish within {ESTOP_ANSWER * 1000:.0f} ms (still trying)"
        return {"acknowledged": False, "latency_ms": ESTOP_ANSWER * 1000.0, "reason": reason, **self.status()}

    # Live runs -------------------------------------------------------------------------------
    def start_run(self, body: RobotRunCreate) -> LiveRun:
        link = self._connected()
        with self._lock:
            if self.run is not None and not self.run.done.is_set():
                raise RobotUnavailable("a live run is in progress; stop it first")
            if link.state not in (LinkState.DISARMED, LinkState.ARMED):
                raise RobotUnavailable(f"the robot is {link.state.value}; it must be disarmed or armed to start")
            legs = [LegControl.from_degrees(leg.psi0_deg, leg.zeta0) for leg in body.controls]
            for leg in legs:
                link.limits.check(leg.psi0_deg, leg.zeta0)  # a clear 422 before anything moves
            run = LiveRun(body)
            self.run = run
        threading.Thread(target=self._execute, args=(run, legs), name="live-run", daemon=True).start()
        return run

    def stop_run(self) -> dict:
        if self.run is None:
            raise NotFound("live run", 0)
        self.run.stop_requested.set()
        self.run.done.wait(10)
        return self.status()

    def _execute(self, run: LiveRun, legs: list[LegControl]) -> None:
        from sim_core.closed_loop import pid_step  # loaded before the first touchdown, not with the service

        link, tracker = self.link, self.tracker
        first_pose = tracker.count()
        controller = self._controller(run.request, legs)
        commanded = run.commanded
        commanded.update({Leg.LEFT: legs[0], Leg.RIGHT: legs[1]})
        integral, previous_error = 0.0, math.nan
        seen_poses = first_pose

        def send(leg: Leg, control: LegControl, why: str) -> None:
            link.set_leg(leg, control.psi0_deg, control.zeta0)
            commanded[leg] = control
            run.commands.append({"time": time.time(), "leg": leg.name.lower(), "psi0_deg": control.psi0_deg,
                                 "zeta0": control.zeta0, "why": why})  # fmt: skip

        def leg_for(k: int) -> LegControl:
            # Detected touchdown k is the climb's touchdown k + 1: even climb touchdowns are the left leg's.
            return run_controls[k] if k < len(run_controls) else commanded[Leg.of(wall_of(k + 1))]

        run_controls = run.touchdown_controls
        try:
            send(Leg.LEFT, legs[0], "start")
            send(Leg.RIGHT, legs[1], "start")
            if link.state == LinkState.DISARMED:
                link.arm()
            link.start()
            deadline = time.monotonic() + run.request.max_seconds
            while True:
                if run.stop_requested.is_set():
                    run.end_reason = run.end_reason or "stopped"
                elif link.state != LinkState.RUNNING:
                    run.end_reason = {
                        LinkState.DISCONNECTED: "link lost",
                        LinkState.ESTOPPED: "e-stop",
                    }.get(link.state, "robot disarmed (fell or timed out)")
                elif time.monotonic() > deadline:
                    run.end_reason = "time limit"
                if run.end_reason is not None:
                    break
                if link.telemetry is not None and (not run.telemetry or run.telemetry[-1]["seq"] != link.telemetry.seq):
                    run.telemetry.append({"time": time.time(), **_telemetry(link.telemetry)})
                if tracker.count() == seen_poses:
                    time.sleep(POLL)  # nothing new to analyse
                    continue
                seen_poses = tracker.count()
                poses = tracker.poses_from(first_pose)
                if len(poses) > 1:
                    times = np.array([p.time for p in poses])
                    found = detect_touchdowns(times, np.array([p.x for p in poses]), np.array([p.y for p in poses]),
                                              self.robot, leg_for)  # fmt: skip
                    while len(run_controls) < len(found):
                        run_controls.append(leg_for(len(run_controls)))
                    for touchdown in found[len(run.touchdowns) :]:
                        run.touchdowns.append(touchdown)
                        if controller is not None:
                            error = controller["target_m"] - touchdown.body_height
                            command, integral = pid_step(error / self.robot.leg_length, previous_error, integral,
                                                         *controller["law"])  # fmt: skip
                            previous_error = error / self.robot.leg_length
                            leg = Leg.of(wall_of(touchdown.index + 2))  # the next touchdown's (climb numbering)
                            send(
                                leg, LegControl(commanded[leg].psi0, command), f"pid after touchdown {touchdown.index}"
                            )
                    if len(run.touchdowns) >= run.request.jumps:
                        run.end_reason = "jumps done"
                        break
                time.sleep(POLL)
        except (LinkError, ParameterError) as error:
            run.end_reason = run.end_reason or f"error: {error}"
        finally:
            run.disarm = _end_safely(link)  # whatever ended it, and whatever the link believes
            self._store(run, tracker, first_pose, run_controls, link)
            run.done.set()

    def _controller(self, body: RobotRunCreate, legs: list[LegControl]) -> dict | None:
        from sim_core.sweep import find_in_place_zeta0

        loop = body.closed_loop
        if loop is None:
            return None
        hover = find_in_place_zeta0(self.robot.to_model(), legs[0].psi0, zeta0_range=(loop.zeta0_min, loop.zeta0_max))
        return {"target_m": loop.target_m, "law": (hover, loop.kp, loop.ki, loop.kd, loop.zeta0_min, loop.zeta0_max)}

    def _store(self, run: LiveRun, tracker, first_pose: int, controls: list[LegControl], link) -> None:
        poses = tracker.poses_from(first_pose)
        frames = {name: np.array([getattr(p, name) for p in poses]) for name in ("time", "x", "y", "pitch")}
        touchdowns = run.touchdowns
        model = self.robot.to_model()
        analysis = touchdown_results(touchdowns, controls, self.robot)
        results = {
            "end_reason": run.end_reason,
            "disarm": run.disarm,
            **analysis,
            "touchdown_controls": [[leg.psi0_deg, leg.zeta0] for leg in controls[: len(touchdowns)]],
            "commands": run.commands,
            "telemetry": run.telemetry,
            "transitions": _transitions(link.transitions),
            "tracker": {"frames": len(poses), "dropped": tracker.stats.dropped, "loss": tracker.stats.loss},
            "calibration": asdict(tracker.calibration),
            "closed_loop": None if run.request.closed_loop is None else run.request.closed_loop.model_dump(),
        }
        request = run.request
        first = request.controls[0]
        with self.sessions() as session:
            stored = Run(
                experiment_id=request.experiment_id,
                kind="robot",
                status="done" if run.end_reason in ("jumps done", "stopped", "time limit") else "failed",
                duration_s=time.time() - run.started,
                code_version=current_code_version(),
                model=json_safe(asdict(model)),
                controls=[[leg.psi0_deg, leg.zeta0] for leg in request.controls],
                jumps=request.jumps,
                alpha=model.alpha,
                psi0_deg=first.psi0_deg,
                zeta0=first.zeta0,
                **touchdown_columns(touchdowns, analysis),
                results=json_safe(results),
                trajectory=pack_trajectory(frames) if poses else None,
            )
            stored.run_tags = [RunTag(tag=tag) for tag in sorted(set(request.tags))]
            session.add(stored)
            session.commit()
            run.stored_run_id = stored.id


def touchdown_columns(touchdowns: list[Touchdown], analysis: dict) -> dict:
    """The stored run's columns its touchdowns decide (a robot run or its replay): the first
    section state, the jumps between touchdowns and their climb; a tracked run has no failure code."""
    return {
        "start_state": json_safe(list(touchdowns[0].state) if touchdowns else [math.nan, math.nan]),
        "failure_code": None,
        "jumps_completed": max(len(touchdowns) - 1, 0),
        "climb": float(np.sum(analysis["rises"])),
    }


def touchdown_results(touchdowns: list[Touchdown], controls: list[LegControl], robot) -> dict:
    """What a robot or replay run stores about its touchdowns: each touchdown, its section state,
    the height gains, and the model's prediction from the first touchdown with the same controls."""
    from sim_core.poincare import iterate_map

    gains = height_gains(touchdowns, robot) if len(touchdowns) > 1 else np.empty(0)
    prediction = None
    if len(touchdowns) > 1:
        schedule = ControlSchedule.of(*controls[: len(touchdowns)])
        prediction = iterate_map(robot.to_model(), schedule, touchdowns[0].state, len(touchdowns) - 1).to_dict()
    return {
        "touchdowns": [vars(td) for td in touchdowns],
        "states": [list(td.state) for td in touchdowns],
        "rises": gains.tolist(),
        "prediction": prediction,
    }


def _transitions(transitions) -> list[dict]:
    return [{"time": t.time, "from": t.before.value, "to": t.after.value, "reason": t.reason} for t in transitions]


def replay_run(session, run_id: int, robot=None) -> Run:
    """A stored robot run's tracker frames analysed again (kind ``replay``): touchdowns, gains and
    the model's prediction, with today's detection — e.g. after a calibration or detector change."""
    robot = robot or get_preset("paper")
    source = session.get(Run, run_id)
    if source is None:
        raise NotFound("run", run_id)
    if source.kind != "robot" or source.trajectory is None:
        raise Conflict(f"run {run_id} is a {source.kind} run without tracker frames; only robot runs can be replayed")
    frames = unpack_trajectory(source.trajectory)
    recorded = [LegControl.from_degrees(*pair) for pair in source.results.get("touchdown_controls", [])]
    alternating = [LegControl.from_degrees(*pair) for pair in source.controls]

    def leg_for(k: int) -> LegControl:
        return recorded[k] if k < len(recorded) else alternating[(k + 1) % 2]

    touchdowns = detect_touchdowns(frames["time"], frames["x"], frames["y"], robot, leg_for)
    analysis = touchdown_results(touchdowns, [leg_for(k) for k in range(len(touchdowns))], robot)
    replay = Run(
        experiment_id=source.experiment_id,
        kind="replay",
        status="done",
        duration_s=0.0,
        code_version=current_code_version(),
        model=source.model,
        controls=source.controls,
        jumps=source.jumps,
        alpha=source.alpha,
        psi0_deg=source.psi0_deg,
        zeta0=source.zeta0,
        **touchdown_columns(touchdowns, analysis),
        results=json_safe({"source_run_id": run_id, **analysis}),
        trajectory=None,
    )
    replay.run_tags = [RunTag(tag=tag) for tag in sorted({*source.tags, "replay"})]
    session.add(replay)
    session.commit()
    return replay


def _telemetry(telemetry) -> dict:
    return {
        "seq": telemetry.seq,
        "state": telemetry.state.name.lower(),
        "psi_servo_deg": list(telemetry.psi_servo_deg),
        "zeta_servo": list(telemetry.zeta_servo),
        "battery_mv": telemetry.battery_mv,
        "faults": telemetry.faults,
    }


def _end_safely(link: RobotLink) -> str:
    """A run's ending: DISARM confirmed by telemetry (:meth:`RobotLink.make_safe`), or why not — a
    lost link's robot disarms itself by its watchdog, and the supervisor disarms it when it is back."""
    try:
        return link.make_safe().value
    except LinkError as error:
        return f"not confirmed: {error}"
