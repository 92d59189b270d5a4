"""A closed loop whose tracker goes silent: how long from the last frame to the robot disarmed.

The robot service (in this process, SQLite in a temporary directory) runs a closed loop on the
virtual robot in real time; its tracker stream passes a relay (tests/tracker_relay.py) that stops
forwarding ``--after`` seconds into the run, as a camera, its software or a switch stopping would.
A watcher thread polls the virtual robot's firmware every 0.5 ms and notes when it leaves
``running``. Per run: the controller, the bound (``tracker_timeout_ms``), the end reason, the stored
status, and the milliseconds from the last frame the relay forwarded to the robot disarmed.
``--lose-body`` streams NatNet and, instead of stopping, marks the robot's rigid body untracked.

Before this bound existed (issue 38): lqr kept ``running`` 26.7-27.0 s with touchdowns frozen until
the body fell to the floor; pid ran blind 37.4 s to its time limit and was stored as done.

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_tracker_silence.py [--runs 3] [--controllers lqr pid]
        [--bounds 100] [--after 4] [--lose-body] [--json]
"""

from __future__ import annotations

import argparse
import json
import socket
import statistics
import tempfile
import threading
import time
from dataclasses import replace
from pathlib import Path

from backend.repositories import runs as run_store
from backend.robot.messages import RobotState
from backend.robot.natnet import parse_version
from backend.robot.natnet_frame import decode_frame, encode_frame
from backend.robot.virtual import VirtualRobot
from backend.schemas import ClosedLoopIn, LegIn, RobotConnect, RobotRunCreate
from backend.services.robot import RobotService
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from sim_core.model.noise import NO_NOISE
from tests.helpers import free_port
from tests.tracker_relay import TrackerRelay

LEGS = [LegIn(psi0_deg=35.0, zeta0=0.9)] * 2
NATNET = parse_version("3.1")


def _untracked(data: bytes) -> bytes:
    frame = decode_frame(data, NATNET)
    return encode_frame(frame.number, frame.timestamp, replace(frame.rigid_body(1), tracked=False), NATNET)


def one_run(sessions, controller: str, bound_ms: float, after_s: float, lose_body: bool, seed: int) -> dict:
    service = RobotService(sessions)
    tracker_port = free_port(socket.SOCK_DGRAM)
    relay = TrackerRelay(("127.0.0.1", tracker_port)).start()
    protocol = {"tracker_protocol": "natnet", "natnet_version": "3.1"} if lose_body else {}
    robot = VirtualRobot(tracker_to=("127.0.0.1", relay.port), noise=NO_NOISE, speed=1.0, seed=seed,
                         **protocol).start()  # fmt: skip
    left_running: list[float] = []
    watching = threading.Event()

    def watch() -> None:
        while not watching.is_set():
            if robot.firmware.state == RobotState.RUNNING:
                break
            time.sleep(0.0005)
        while not watching.is_set():
            if robot.firmware.state != RobotState.RUNNING:
                left_running.append(time.monotonic())
                return
            time.sleep(0.0005)

    try:
        connect = {"natnet_multicast_group": None, **protocol} if lose_body else {}
        service.connect(RobotConnect(url=robot.url, tracker_port=tracker_port, **connect))
        watcher = threading.Thread(target=watch, daemon=True)
        watcher.start()
        loop = ClosedLoopIn(target_m=0.4, controller=controller)
        service.start_run(RobotRunCreate(controls=LEGS, jumps=300, max_seconds=120, closed_loop=loop,
                                         tracker_timeout_ms=bound_ms))  # fmt: skip
        time.sleep(after_s)
        if lose_body:
            relay.rewrite = _untracked
            blinded = time.monotonic()
        else:
            relay.silence()
            blinded = None
        run = service.wait_run(60.0)
        watching.set()
        watcher.join(2)
        last_frame = blinded if lose_body else relay.last_forwarded
        with sessions() as session:
            stored = run_store.get_run(session, run.run_id)
            status = stored.status
        return {
            "controller": controller,
            "bound_ms": bound_ms,
            "end_reason": run.end_reason,
            "status": status,
            "disarm": run.disarm,
            "touchdowns": len(run.touchdowns),
            "last_frame_to_disarmed_ms": None if not left_running else (left_running[0] - last_frame) * 1000.0,
        }
    finally:
        service.close()
        robot.stop()
        relay.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs per controller and bound")
    parser.add_argument("--controllers", nargs="+", default=["lqr", "pid"])
    parser.add_argument("--bounds", nargs="+", type=float, default=[100.0], help="tracker_timeout_ms values")
    parser.add_argument("--after", type=float, default=4.0, help="seconds into the run the tracker stops")
    parser.add_argument("--lose-body", action="store_true", help="NatNet: the body untracked instead of silence")
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="parkour-silence-"))
    engine = make_engine(sqlite_url(folder))
    migrate(engine)
    sessions = session_factory(engine)
    rows = []
    for controller in options.controllers:
        for bound in options.bounds:
            for seed in range(options.runs):
                rows.append(one_run(sessions, controller, bound, options.after, options.lose_body, seed))
                if not options.json:
                    print(rows[-1], flush=True)
    delays = [row["last_frame_to_disarmed_ms"] for row in rows if row["last_frame_to_disarmed_ms"] is not None]
    summary = {"runs": rows, "max_ms": max(delays, default=None),
               "median_ms": statistics.median(delays) if delays else None}  # fmt: skip
    print(json.dumps(summary, indent=1) if options.json else {k: v for k, v in summary.items() if k != "runs"})


if __name__ == "__main__":
    main()
