"""A finished robot run in the store, made without a robot or real time: the simulator's climb as
the tracker's frames, journaled in two entries (JSON-safe: a missing pitch as null) and folded as
the journal writer does.

The tracker clock starts at :data:`TRACKER_EPOCH` (a camera's clock is not the run's), a few
frames have no pitch, and the run has commands, telemetry and link changes stamped in Unix time
(:func:`store_robot_run`: as runs stored them before they stamped the tracker's time too).
:func:`store_lagging_run` is a closed loop whose frames arrived at a fraction of real time, its
commands and telemetry stamped on both clocks as a live run stamps them.
"""

from __future__ import annotations

import datetime
import math

import numpy as np

from backend.repositories import runs as run_store
from backend.robot.touchdown import detect_touchdowns
from backend.robot.tracker import Calibration
from backend.schemas import LegIn, RobotRunCreate
from backend.services.robot_records import fold_journal, open_robot_run
from backend.store.models import RunJournal
from experiments.manifest import json_safe
from sim_core import ControlSchedule, find_fixed_point, get_preset, simulate_trajectory

TRACKER_EPOCH = 1000.0  # [s] the tracker's time of the run's first frame
JUMPS = 6
LEGS = ((30.0, 0.87), (30.0, 0.9))
REQUEST = RobotRunCreate(controls=[LegIn(psi0_deg=p, zeta0=z) for p, z in LEGS], jumps=JUMPS - 1, tags=["lab"])


def climb_frames(jumps: int = JUMPS) -> dict[str, np.ndarray]:
    """The paper's period-2 gait climbing ``jumps`` jumps, as 100 Hz tracker frames (SI, wall coordinates)."""
    robot = get_preset("paper")
    model = robot.to_model()
    schedule = ControlSchedule.from_degrees(LEGS)
    gait = find_fixed_point(model, schedule, 2, (-0.8, -0.15))
    path = simulate_trajectory(model, schedule, gait.state, jumps, sample_rate=100.0 * robot.scales.time).to_si(robot)
    pitch = np.full(path.time.size, 0.02)
    pitch[::7] = math.nan  # frames the markers gave no pitch
    return {"time": path.time + TRACKER_EPOCH, "x": path.x, "y": path.y, "pitch": pitch}


def store_robot_run(session) -> int:
    """A robot run stored as a live run stores one (opened, journaled, folded ``done``); its id."""
    robot = get_preset("paper")
    schedule = ControlSchedule.from_degrees(LEGS)
    frames = climb_frames()
    touchdowns = detect_touchdowns(frames["time"], frames["x"], frames["y"], robot, lambda k: schedule[k + 1])
    half = frames["time"].size // 2
    split = frames["time"][half]

    def entries(start: float) -> list[dict]:  # start: the run's creation in Unix time
        return [{
            "frames": {name: values[lo:hi].tolist() for name, values in frames.items()},
            "touchdowns": [
                {"touchdown": td.to_dict(), "control": [schedule[td.index + 1].psi0_deg, schedule[td.index + 1].zeta0]}
                for td in touchdowns
                if (td.time < split) == (first == 0)
            ],
            "commands": [_command(start + 0.01 * leg, leg) for leg in (0, 1)] if first == 0 else [_command(start + 2)],
            "telemetry": [_telemetry(start + 0.1 * (seq + 1), seq) for seq in range(3 * first, 3 * first + 3)],
            "transitions": [{"time": start + 0.05, "from": "disarmed", "to": "armed", "reason": "arm"}] * (1 - first),
            "tracker": {"dropped": 2 * first, "loss": 0.001 * first},
        } for first, (lo, hi) in enumerate(((0, half), (half, frames["time"].size)))]  # fmt: skip

    return store_journaled_run(session, REQUEST, entries, disarm="disarmed")


LAG_SPEED = 0.37  # the tracker's seconds per Unix second in the lagging run (issue 40's robot)
FIRST_FRAME_AFTER = 0.02  # [s] from the run's start to its first frame's arrival
DETECTED_AFTER = 0.15  # [s] of tracker time from a touchdown to the frame that shows it (its flight begun)
TELEMETRY_EVERY = 0.05  # [s] Unix time between telemetry


def store_lagging_run(session, speed: float = LAG_SPEED) -> int:
    """A closed-loop robot run whose tracker frames arrived at ``speed`` times real time; its id.

    Frame time ``t`` arrives at Unix time ``start + FIRST_FRAME_AFTER + (t - TRACKER_EPOCH) / speed``.
    Stamped as a live run stamps them (``tracker_time``: the newest frame received then, None before
    the first): the two start commands; after each touchdown, a command at the arrival of the
    first frame ``DETECTED_AFTER`` past it (1 ms later); telemetry every ``TELEMETRY_EVERY`` s.
    Link changes carry Unix time only: armed before the first frame, running at frame 100's
    arrival (1 ms later), disarmed 0.2 s after the last."""
    robot = get_preset("paper")
    schedule = ControlSchedule.from_degrees(LEGS)
    frames = climb_frames()
    times = frames["time"]
    touchdowns = detect_touchdowns(times, frames["x"], frames["y"], robot, lambda k: schedule[k + 1])

    def entries(start: float) -> list[dict]:
        arrivals = start + FIRST_FRAME_AFTER + (times - TRACKER_EPOCH) / speed

        def stamped(at: float) -> dict:
            newest = int(np.searchsorted(arrivals, at, side="right")) - 1
            return {"time": at, "tracker_time": float(times[newest]) if newest >= 0 else None}

        law = [
            _command(0, 1 - td.index % 2)
            | {"why": f"pid after touchdown {td.index}", "controller": "pid", "clipped": False, "state": [0.1, None]}
            | stamped(float(arrivals[np.searchsorted(times, td.time + DETECTED_AFTER)]) + 0.001)
            for td in touchdowns
            if td.time + DETECTED_AFTER <= times[-1]
        ]
        end = float(arrivals[-1]) + 0.2
        telemetry = [_telemetry(0, seq) | stamped(at) for seq, at in enumerate(np.arange(start, end, TELEMETRY_EVERY))]
        transitions = [
            {"time": start + 0.01, "from": "disarmed", "to": "armed", "reason": "arm"},
            {"time": float(arrivals[100]) + 0.001, "from": "armed", "to": "running", "reason": "start"},
            {"time": end, "from": "running", "to": "disarmed", "reason": "jumps done"},
        ]
        return [{
            "frames": {name: values.tolist() for name, values in frames.items()},
            "touchdowns": [
                {"touchdown": td.to_dict(), "control": [schedule[td.index + 1].psi0_deg, schedule[td.index + 1].zeta0]}
                for td in touchdowns
            ],
            "commands": [_command(0, leg) | stamped(start + 0.001 * leg) for leg in (0, 1)] + law,
            "telemetry": telemetry,
            "transitions": transitions,
            "tracker": {"dropped": 0, "loss": 0.0},
        }]  # fmt: skip

    return store_journaled_run(session, REQUEST, entries, disarm="disarmed")


def store_journaled_run(
    session, request: RobotRunCreate, entries, *, disarm: str = "confirmed", end_reason: str = "jumps done"
) -> int:
    """A robot run opened for ``request``, journaled with the entries ``entries(start)`` gives
    (``start``: the run's creation, Unix time) a second apart, and folded ``done`` as the journal
    writer folds one; its id."""
    robot = get_preset("paper")
    run_id = open_robot_run(session, request, robot, Calibration())
    created = run_store.get_run(session, run_id).created_at.replace(tzinfo=datetime.UTC)
    for index, entry in enumerate(entries(created.timestamp())):
        written = created + datetime.timedelta(seconds=index + 1)
        session.add(RunJournal(run_id=run_id, data=json_safe(entry), written_at=written))
    session.commit()
    fold_journal(session, run_id, status="done", end_reason=end_reason, disarm=disarm, robot=robot)
    return run_id


def _command(time: float, leg: int = 0) -> dict:
    psi0_deg, zeta0 = LEGS[leg]
    return {"time": time, "leg": ("left", "right")[leg], "psi0_deg": psi0_deg, "zeta0": zeta0, "why": "start"}


def _telemetry(time: float, seq: int) -> dict:
    return {"time": time, "seq": seq, "state": "running", "psi_servo_deg": [30.0, 30.0], "zeta_servo": [0.87, 0.9],
            "battery_mv": 7400, "faults": 0}  # fmt: skip
