"""E-stop through the API, as the panel presses it (no token): normally, while compute fills the
request thread pool, and with the PC->robot line jammed (tests/robot_rig.py's pty robot).

In-process (FastAPI's TestClient), against the virtual robot. ``http`` is the round trip of
``POST /api/v1/robot/estop``; ``ack`` the link's own e-stop-to-acknowledgement latency.

Usage: python scripts/bench_estop_api.py [--repeats 100]
"""

from __future__ import annotations

import argparse
import json
import socket
import statistics
import tempfile
import threading
import time
from pathlib import Path

from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.robot.messages import RobotState
from backend.robot.virtual import VirtualRobot
from backend.services.simulation import KERNEL_LOCK
from backend.settings import Settings
from tests.helpers import free_port
from tests.robot_rig import PtyRobot

POOL_FILLERS = 45  # more than the request pool's 40 threads
MAP_BODY = {"controls": [{"psi0_deg": 30, "zeta0": 0.87}], "start": {"xdot": -0.9, "ydot": -0.2}, "jumps": 3}


def percentiles(values: list[float]) -> dict:
    values = sorted(values)
    return {
        "n": len(values),
        "p50_ms": round(statistics.median(values), 2),
        "p99_ms": round(values[int(0.99 * (len(values) - 1))], 2),
        "max_ms": round(values[-1], 2),
    }


def press(client: TestClient, repeats: int, between=None) -> tuple[list[float], list[dict]]:
    wall, answers = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        answers.append(client.post("/api/v1/robot/estop").json())
        wall.append((time.perf_counter() - started) * 1000)
        if between is not None:
            between()
    return wall, answers


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=100)
    options = parser.parse_args()
    result = {}
    with tempfile.TemporaryDirectory() as data, TestClient(create_app(Settings.from_environment(Path(data)))) as client:
        auth = {"Authorization": "Bearer " + (Path(data) / "api_token").read_text().strip()}
        tracker = free_port(socket.SOCK_DGRAM)
        robot = VirtualRobot().start()
        client.post("/api/v1/robot/connect", json={"url": robot.url, "tracker_port": tracker}, headers=auth)

        def rearm():
            client.post("/api/v1/robot/reset", headers=auth)
            client.post("/api/v1/robot/arm", headers=auth)

        rearm()
        wall, answers = press(client, options.repeats, rearm)
        assert all(answer["acknowledged"] for answer in answers), answers
        result["normal"] = {"http": percentiles(wall), "ack": percentiles([a["latency_ms"] for a in answers])}
        fillers = [
            threading.Thread(target=client.post, args=("/api/v1/sim/map",), kwargs={"json": MAP_BODY}, daemon=True)
            for _ in range(POOL_FILLERS)
        ]
        with KERNEL_LOCK:  # a long computation holds every request thread
            for filler in fillers:
                filler.start()
            time.sleep(0.5)
            wall, answers = press(client, options.repeats)  # the robot stays latched: re-arming needs the pool
        for filler in fillers:
            filler.join(60)
        assert all(answer["acknowledged"] for answer in answers), answers
        result["pool_full"] = {"http": percentiles(wall), "ack": percentiles([a["latency_ms"] for a in answers])}
        client.post("/api/v1/robot/disconnect", headers=auth)
        robot.stop()
        rig = PtyRobot(RobotState.ARMED).start()
        client.post("/api/v1/robot/connect", json={"url": rig.path, "tracker_port": tracker}, headers=auth)
        rig.jam()
        wall, answers = press(client, min(options.repeats, 20))
        result["jammed"] = {
            "http": percentiles(wall),
            "acknowledged": sum(answer["acknowledged"] for answer in answers),
            "reasons": sorted({answer.get("reason") for answer in answers}),
        }
        client.post("/api/v1/robot/disconnect", headers=auth)
        rig.stop()
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
