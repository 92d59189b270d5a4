"""E-stop through the API, as the panel presses it (no token), on the real service: normally, while
a heavy job and 45 clients saturate it, during a flood of line noise, and with the PC->robot line
jammed.

The service is ``parkour serve --no-view`` on a free port, SQLite in a temporary data directory;
the virtual robot is ``parkour robot-sim`` in its own process. Each condition presses the e-stop
``--repeats`` times, re-arming between presses (RESET, ARM: the token's calls) where the line lets
it, and reports two latencies:

- ``http``: the round trip of ``POST /api/v1/robot/estop`` as a client sees it (the service
  promises an answer within 200 ms);
- ``ack``: the link's own e-stop to acknowledgement (``latency_ms`` in the answer).

Conditions:

- ``normal``: nothing else running;
- ``saturated``: an MJTF job of 1408 chunks running (tests/helpers.py's HEAVY_JOB, past its first
  chunk) and 45 clients POSTing ``/api/v1/sim/map`` back to back from another process, so all of
  the request pool's 40 threads are taken; ``rearm`` is how long the RESET and ARM between presses
  took, since they wait for a pool thread;
- ``flood``: the robot behind a pty (tests/robot_rig.py's answering PtyRobot) while it floods the
  line with random bytes and broken frames at 100 kB/s;
- ``jammed``: a robot behind a pty whose PC->robot direction is full, so every write blocks; the
  e-stop cannot be acknowledged, and nothing can re-arm between presses (``acknowledged`` counts).

Usage, from the checkout's root:

    PYTHONPATH=. python scripts/bench_estop_api.py [--repeats 100] [--clients 45] [--json]
"""

from __future__ import annotations

import argparse
import json
import socket
import statistics
import tempfile
import time
from pathlib import Path

import httpx

from backend.robot.firmware import Firmware
from backend.robot.messages import RobotState
from tests.helpers import (
    HEAVY_JOB,
    POOL_FILLERS,
    free_port,
    start_map_load,
    start_robot_sim,
    start_service,
    stop_map_load,
    stop_processes,
)
from tests.robot_rig import PtyRobot

JOB_START_S = 120.0  # [s] for the heavy job's first chunk (its kernels loaded)
TIMEOUT_S = 60.0  # [s] any one request: a bound, not a measurement
REARM_STEPS = 6


def percentiles(values: list[float]) -> dict:
    values = sorted(values)
    if not values:
        return {"n": 0}
    return {
        "n": len(values),
        "p50_ms": round(statistics.median(values), 2),
        "p99_ms": round(values[int(0.99 * (len(values) - 1))], 2),
        "max_ms": round(values[-1], 2),
    }


class Bench:
    def __init__(self, base: str, token: str, tracker_port: int):
        self.client = httpx.Client(base_url=base, timeout=TIMEOUT_S)
        self.auth = {"Authorization": f"Bearer {token}"}
        self.tracker_port = tracker_port

    def call(self, path: str, **body) -> dict:
        response = self.client.post(path, json=body or None, headers=self.auth)
        if response.status_code != 200:
            raise SystemExit(f"{path}: {response.status_code} {response.text}")
        return response.json()

    def connect(self, url: str) -> str:
        return self.call("/api/v1/robot/connect", url=url, tracker_port=self.tracker_port)["state"]

    def rearm(self, failures: list[str]) -> float:
        """RESET (if e-stopped) and ARM (if disarmed) until armed, in at most REARM_STEPS calls (each
        refusal, a 503, is noted in ``failures``); returns how long it took [ms]."""
        started = time.perf_counter()
        state = "estopped"
        for _ in range(REARM_STEPS):
            if state == "armed":
                return (time.perf_counter() - started) * 1000
            call = {"estopped": "reset", "disarmed": "arm"}.get(state)
            if call is None:
                raise SystemExit(f"the robot is {state}: nothing re-arms it")
            response = self.client.post(f"/api/v1/robot/{call}", headers=self.auth)
            if response.status_code != 200:
                failures.append(f"{call}: {response.status_code} {response.json()['detail']}")
            state = self.client.get("/api/v1/robot").json()["state"]
        raise SystemExit(f"could not re-arm the robot: {failures[-REARM_STEPS:]}")

    def press(self, repeats: int, *, rearm: bool) -> dict:
        http, ack, rearms, acknowledged, reasons, failures = [], [], [], 0, set(), []
        for _ in range(repeats):
            if rearm:
                rearms.append(self.rearm(failures))
            started = time.perf_counter()
            response = self.client.post("/api/v1/robot/estop")  # no token: stopping is always allowed
            http.append((time.perf_counter() - started) * 1000)
            answer = response.json()
            if response.status_code != 200:
                raise SystemExit(f"e-stop answered {response.status_code}: {response.text}")
            if answer["acknowledged"]:
                acknowledged += 1
                ack.append(answer["latency_ms"])
            else:
                reasons.add(answer["reason"])
        result = {"presses": repeats, "acknowledged": acknowledged, "http": percentiles(http), "ack": percentiles(ack)}
        if rearms:
            result["rearm"] = percentiles(rearms)
            result["rearm_failures"] = failures
        if reasons:
            result["reasons"] = sorted(reasons)
        return result


def measure(repeats: int, clients: int) -> dict:
    result = {}
    with tempfile.TemporaryDirectory(prefix="bench-estop-") as data:
        port, tracker_port = free_port(), free_port(socket.SOCK_DGRAM)
        service = start_service(Path(data), port, "--no-view")
        robot_port = free_port()
        robot = start_robot_sim(robot_port, tracker_port)
        base = f"http://127.0.0.1:{port}"
        bench = Bench(base, (Path(data) / "api_token").read_text().strip(), tracker_port)
        try:
            bench.connect(f"socket://127.0.0.1:{robot_port}")
            result["normal"] = bench.press(repeats, rearm=True)

            job = bench.client.post("/api/v1/jobs", json=HEAVY_JOB, headers=bench.auth).json()
            deadline = time.monotonic() + JOB_START_S
            while bench.client.get(f"/api/v1/jobs/{job['id']}").json()["completed"] == 0:
                if time.monotonic() > deadline:
                    raise SystemExit("the heavy job did not get going")
                time.sleep(0.1)
            load = start_map_load(base, clients)
            try:
                result["saturated"] = bench.press(repeats, rearm=True)
                result["saturated"]["job_state"] = bench.client.get(f"/api/v1/jobs/{job['id']}").json()["state"]
                result["saturated"]["counters"] = bench.client.get("/api/v1/robot").json()["counters"]
            finally:
                result["saturated_load"] = stop_map_load(load)
                bench.call(f"/api/v1/jobs/{job['id']}/cancel")

            rig = PtyRobot(firmware=Firmware()).start()
            try:
                bench.connect(rig.path)
                flood = rig.flood()
                result["flood"] = bench.press(repeats, rearm=True)
                rig.stop_flood()
                result["flood"]["line_noise_bytes"] = flood.bytes
                result["flood"]["counters"] = bench.client.get("/api/v1/robot").json()["counters"]
            finally:
                bench.call("/api/v1/robot/disconnect")
                rig.stop()

            rig = PtyRobot(RobotState.ARMED).start()
            try:
                bench.connect(rig.path)
                rig.jam()
                result["jammed"] = bench.press(repeats, rearm=False)
            finally:
                bench.call("/api/v1/robot/disconnect")
                rig.stop()
        finally:
            bench.client.close()
            stop_processes(robot, service)
    return result


def table(result: dict) -> str:
    def cell(stats: dict, key: str) -> str:
        return f"{stats[key]:.1f}" if key in stats else "-"

    rows = ["condition   acknowledged  http p50  http p99  http max   ack p50  ack p99  ack max   [ms]"]
    for name in ("normal", "saturated", "flood", "jammed"):
        entry = result[name]
        http, ack = entry["http"], entry["ack"]
        rows.append(
            f"{name:<11} {entry['acknowledged']:>5}/{entry['presses']:<6} {cell(http, 'p50_ms'):>9} "
            f"{cell(http, 'p99_ms'):>9} {cell(http, 'max_ms'):>9} {cell(ack, 'p50_ms'):>9} "
            f"{cell(ack, 'p99_ms'):>8} {cell(ack, 'max_ms'):>8}"
        )
    for name in ("normal", "saturated", "flood"):
        entry = result[name]
        rows.append(
            f"{name}: RESET+ARM between presses p50 {entry['rearm']['p50_ms']:.0f} ms, max "
            f"{entry['rearm']['max_ms']:.0f} ms; {len(entry['rearm_failures'])} refused {entry['rearm_failures'][:2]}"
        )
    for name in ("saturated", "flood"):
        counters = {key: value for key, value in result[name]["counters"].items() if value}
        rows.append(f"{name}: the link's non-zero counters {counters}")
    saturated = result["saturated"]
    rows.append(f"saturated: job {saturated['job_state']} throughout; /sim/map answers {result['saturated_load']}")
    rows.append(f"flood: {result['flood']['line_noise_bytes']} bytes of line noise")
    for name in ("saturated", "flood", "jammed"):
        if result[name].get("reasons"):
            rows.append(f"{name}: not acknowledged because {result[name]['reasons']}")
    return "\n".join(rows)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=100)
    parser.add_argument("--clients", type=int, default=POOL_FILLERS)
    parser.add_argument("--json", action="store_true")
    options = parser.parse_args()
    result = measure(options.repeats, options.clients)
    print(json.dumps(result, indent=1) if options.json else table(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
