"""Robot runs in the store: opened when they start, journaled while they run, folded when they end.

A live run is a row of kind ``robot`` from its first moment (status ``running``,
:func:`open_robot_run`). While it runs, its journal writer appends what it recorded
(:class:`~backend.store.models.RunJournal` entries, :mod:`backend.services.robot_journal`). When
it ends, :func:`fold_journal` turns the entries into the run's results and tracker frames —
touchdowns and the model's prediction beside them — and deletes them. A run the service did not
live to end is folded the same way at the next start (:func:`recover_interrupted`), as
``interrupted``: everything to its last journal entry is kept, and nothing is re-armed.

A stored run's frames can be analysed again with today's detector (:func:`replay_run`).
"""

from __future__ import annotations

import datetime
import math
from collections.abc import Callable
from dataclasses import asdict

import numpy as np

from backend.errors import Conflict, NotFound
from backend.repositories import experiments as stored_experiments
from backend.repositories import robot_runs
from backend.repositories import runs as stored_runs
from backend.repositories import worlds as stored_worlds
from backend.robot.run_endings import robot_ending_record
from backend.robot.touchdown import Touchdown, detect_touchdowns, height_gains
from backend.schemas import RunDetail
from backend.services.provenance import current_code_version
from backend.services.robot_plans import world_sides
from backend.services.run_prediction import run_prediction
from backend.services.runs import run_detail
from backend.store.models import Run, World
from backend.store.run_record import RunRecord
from backend.store.trajectory_blob import pack_trajectory, unpack_trajectory
from experiments.manifest import json_safe
from sim_core.model.controls import LegControl
from sim_core.model.presets import get_preset

FRAME_COLUMNS = ("time", "x", "y", "pitch")
INTERRUPTED = "interrupted: the service stopped during the run; kept to its last journal entry"


def open_robot_run(
    session, request, robot, calibration, *, started_by: str | None = None, link: dict | None = None,
    person: str | None = None, legs=None, world_id: int | None = None,
) -> int:  # fmt: skip
    """Store a live run as it starts (status ``running``); returns its id. ``request`` is the
    :class:`~backend.schemas.RobotRunCreate`, ``robot`` the physical parameters, ``started_by`` who
    started it as the panels are told, ``person`` the token's (the run's ``created_by``), ``link``
    the radio link it runs on (``url``, ``robot_address``), ``legs`` its start legs (a plan's, where it
    follows one; else the request's), ``world_id`` the world it climbs."""
    model = robot.to_model()
    if request.experiment_id is not None:  # before anything moves: a 404, and the robot stays as it is
        stored_experiments.locked_experiment(session, request.experiment_id)
    record = RunRecord(
        kind="robot",
        status="running",
        code_version=current_code_version(),
        model=json_safe(asdict(model)),
        controls=[[leg.psi0_deg, leg.zeta0] for leg in (request.controls or legs)],
        world_id=world_id,
        jumps=request.jumps,
        **touchdown_columns([], {"rises": []}),
        results=json_safe(
            {
                "end_reason": None,
                "started_by": started_by,
                "link": link,
                "calibration": asdict(calibration),
                "tracker_timeout_ms": request.tracker_timeout_ms,
                "closed_loop": None if request.closed_loop is None else request.closed_loop.model_dump(),
                "plan_job_id": request.plan_job_id,
            }
        ),
        tags=tuple(request.tags),
    )
    run = stored_runs.add_run(session, record, experiment_id=request.experiment_id, created_by=person)
    session.commit()
    return run.id


def fold_journal(
    session, run_id: int, *, status: str, end_reason: str, disarm: str | None, robot=None, faults=()
) -> Run:
    """The run's journal entries folded into the run (results, tracker frames, the touchdown
    columns) and deleted, in one transaction; ``status`` and ``end_reason`` say how it ended,
    ``faults`` the robot's at the end (names). The results say whether it ``fell`` (its end reason,
    or a FELL fault at the end or in any telemetry it recorded): calibration leaves its fall out."""
    robot = robot or get_preset("paper")
    run = stored_runs.find(session, run_id)
    entries = robot_runs.journal(session, run_id)
    frames = {name: [] for name in FRAME_COLUMNS}
    touchdowns, controls, commands, telemetry, transitions, gaps, tracker = [], [], [], [], [], [], None
    for entry in entries:
        data = entry.data
        for name in FRAME_COLUMNS:
            frames[name].extend(data["frames"][name])
        for stored in data["touchdowns"]:
            touchdowns.append(Touchdown.from_dict(stored["touchdown"]))
            controls.append(LegControl.from_degrees(*stored["control"]))
        commands.extend(data["commands"])
        telemetry.extend(data["telemetry"])
        transitions.extend(data["transitions"])
        gaps.extend(data.get("tracker_gaps", []))  # entries written before gaps were recorded have none
        tracker = data["tracker"] or tracker
    analysis = touchdown_results(touchdowns, controls, robot, _world_of(session, run.world_id))
    run.status = status
    if entries:
        run.duration_s = max(run.duration_s, _seconds_between(run.created_at, entries[-1].written_at))
    run.results = json_safe(
        {
            **run.results,
            "end_reason": end_reason,
            "disarm": disarm,
            **analysis,
            "touchdown_controls": [[leg.psi0_deg, leg.zeta0] for leg in controls],
            "commands": commands,
            "telemetry": telemetry,
            "transitions": transitions,
            "tracker": {"frames": len(frames["time"]), **(tracker or {"dropped": 0, "loss": 0.0})},
            "tracker_gaps": gaps,
            **robot_ending_record(end_reason, faults, telemetry),
        }
    )
    for name, value in touchdown_columns(touchdowns, analysis).items():
        setattr(run, name, value)
    stored_runs.set_outcome(run)  # its end reason and touchdowns as columns
    columns = {name: np.asarray(values, dtype=float) for name, values in frames.items()}
    run.trajectory = pack_trajectory(columns) if frames["time"] else None
    robot_runs.delete_journal(session, run_id)
    session.commit()
    return run


def recover_interrupted(sessions, robot=None) -> list[int]:
    """At start-up: every robot run still ``running`` was cut short by the service's death; fold
    its journal as ``interrupted`` (the disarm unconfirmed: the robot's watchdog saw to it).
    Returns their ids. Nothing is sent to any robot."""
    with sessions() as session:
        ids = robot_runs.running_robot_run_ids(session)
        for run_id in ids:
            fold_journal(session, run_id, status="interrupted", end_reason=INTERRUPTED,
                         disarm="not confirmed: the service stopped", robot=robot)  # fmt: skip
    return list(ids)


def touchdown_columns(touchdowns: list[Touchdown], analysis: dict) -> dict:
    """The stored run's columns its touchdowns decide (a robot run or its replay): the first
    section state, the jumps between touchdowns and their climb; a tracked run has no failure code."""
    return {
        "start_state": json_safe(list(touchdowns[0].state) if touchdowns else [math.nan, math.nan]),
        "failure_code": None,
        "jumps_completed": max(len(touchdowns) - 1, 0),
        "climb": float(np.sum(analysis["rises"])),
    }


def touchdown_results(
    touchdowns: list[Touchdown], controls: list[LegControl], robot, world: World | None = None
) -> dict:
    """What a robot or replay run stores about its touchdowns: each touchdown, its section state,
    the height gains, and the model's prediction from the first touchdown with the same controls
    in the chute the run climbed (``world``, its stored world; None: parallel walls;
    :mod:`backend.services.run_prediction`)."""
    gains = height_gains(touchdowns, robot) if len(touchdowns) > 1 else np.empty(0)
    return {
        "touchdowns": [td.to_dict() for td in touchdowns],
        "states": [list(td.state) for td in touchdowns],
        "rises": gains.tolist(),
        "prediction": run_prediction(touchdowns, controls, robot, world),
    }


def replay_run(session, run_id: int, robot=None, *, person: str | None = None) -> Run:
    """A stored robot run's tracker frames analysed again (kind ``replay``) at ``person``'s asking:
    touchdowns, gains and the model's prediction, with today's detection — e.g. after a calibration
    or detector change."""
    robot = robot or get_preset("paper")
    source = stored_runs.find(session, run_id)
    if source is None:
        raise NotFound("run", run_id)
    if source.kind == "robot" and source.status == "running":
        raise Conflict(f"run {run_id} is still running; replay it once it has ended")
    if source.kind != "robot" or source.trajectory is None:
        raise Conflict(f"run {run_id} is a {source.kind} run without tracker frames; only robot runs can be replayed")
    frames = unpack_trajectory(source.trajectory)
    leg_for = recorded_leg_for(source)
    side_at = None if source.world_id is None else world_sides(session, source.world_id, robot)  # its world's
    touchdowns = detect_touchdowns(frames["time"], frames["x"], frames["y"], robot, leg_for, frames.get("pitch"),
                                   side_at=side_at)  # fmt: skip
    controls = [leg_for(k) for k in range(len(touchdowns))]
    analysis = touchdown_results(touchdowns, controls, robot, _world_of(session, source.world_id))
    record = RunRecord(
        kind="replay",
        status="done",
        world_id=source.world_id,
        code_version=current_code_version(),
        model=source.model,
        controls=source.controls,
        jumps=source.jumps,
        **touchdown_columns(touchdowns, analysis),
        results=json_safe(
            {
                "source_run_id": run_id,
                "closed_loop": source.results.get("closed_loop"),  # driven as the run it replays
                **analysis,
                "touchdown_controls": [[leg.psi0_deg, leg.zeta0] for leg in controls],
            }
        ),
        tags=(*source.tags, "replay"),
    )
    replay = stored_runs.add_run(session, record, experiment_id=source.experiment_id, created_by=person)
    session.commit()
    return replay


def replay(session, run_id: int, *, person: str | None = None) -> RunDetail:
    """:func:`replay_run` with the paper's robot, answered as the API gives a run."""
    return run_detail(replay_run(session, run_id, person=person))


def recorded_leg_for(source: Run) -> Callable[[int], LegControl]:
    """Detected touchdown k's controls in a robot run's replay: the ones the run recorded for it,
    else the run's two legs alternating as the live run commanded them (detected touchdown k is
    the climb's touchdown k + 1)."""
    recorded = [LegControl.from_degrees(*pair) for pair in source.results.get("touchdown_controls", [])]
    alternating = [LegControl.from_degrees(*pair) for pair in source.controls]

    def leg_for(k: int) -> LegControl:
        return recorded[k] if k < len(recorded) else alternating[(k + 1) % 2]

    return leg_for


def _world_of(session, world_id: int | None) -> World | None:
    """The stored world a run climbed (None: parallel walls); one a run uses is never deleted."""
    return None if world_id is None else stored_worlds.get(session, world_id)


def _seconds_between(start: datetime.datetime, end: datetime.datetime) -> float:
    def aware(moment: datetime.datetime) -> datetime.datetime:
        return moment if moment.tzinfo is not None else moment.replace(tzinfo=datetime.UTC)

    return max(0.0, (aware(end) - aware(start)).total_seconds())
