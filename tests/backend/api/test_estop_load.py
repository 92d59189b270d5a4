"""E-stop while the real service is saturated: ``parkour serve`` in a subprocess, over HTTP.

A heavy MJTF job runs and 45 clients (in a process of their own) keep ``POST /api/v1/sim/map``
coming back to back — as in the lab when a study runs and the panel is busy: every core computes
(in the service's worker processes). ``POST /api/v1/robot/estop``, without a token, must still be
answered and acknowledged by the robot. TestClient would run the app in this process behind its
own portal; a real server puts uvicorn's one event loop, its sockets and the service's GIL in the
way, as in the lab. (tests/backend/api/routes/test_robot.py holds every request thread inside a
route instead, which costs the service nothing; here they compute.)

scripts/bench_estop_api.py measures the latency in these conditions.
"""

import socket
import subprocess
import time

import httpx
import pytest

from backend import schemas
from backend.jobs.mjtf import MJTFJobCreate
from backend.robot.firmware import Firmware
from backend.robot.messages import Command, Kind
from backend.robot.virtual import VirtualRobot
from tests.helpers import HEAVY_JOB, MAP_BODY, free_port, start_map_load, start_service, stop_map_load

# A robot answering in real time (the e-stop's 150 ms acknowledgement): ./test.sh runs these alone.
pytestmark = pytest.mark.realtime

PRESSES = 5
ESTOP_BOUND_S = 1.0  # [s] the service promises 200 ms; a generous bound for noisy machines
PROMISE_PRESSES = 50  # enough that a missed press would show (2 in 100 were, with compute in the service's process)
SYNC_BOUND_S = 30.0  # [s] a reset or an arm waits for a pool thread: "answers", not a latency claim
JOB_START_S = 60.0  # [s] the job's first chunk is done (its kernels are loaded): generous


def test_the_heavy_job_and_the_load_are_valid_requests():
    """The job and the /sim/map body above are what the API accepts."""
    assert len(MJTFJobCreate(**HEAVY_JOB).zeta0s) == 11
    assert schemas.MapIn(**MAP_BODY).jumps == 1000


class RecordingFirmware(Firmware):
    """The virtual robot's firmware, noting when (``time.perf_counter``) each ESTOP reached it."""

    def __init__(self):
        super().__init__()
        self.estops: list[float] = []

    def receive(self, message, now):
        if isinstance(message, Command) and message.kind == Kind.ESTOP:
            self.estops.append(time.perf_counter())
        return super().receive(message, now)


@pytest.fixture(scope="module")
def saturated(tmp_path_factory):
    """``(client, auth, robot, job_id)``: the real service on a free port (SQLite in a temporary data
    directory), connected to a virtual robot, while the heavy job runs and the load keeps the pool full."""
    data = tmp_path_factory.mktemp("estop-load") / "data"
    process = start_service(data, 0, "--no-view")
    robot = VirtualRobot(firmware=RecordingFirmware()).start()
    auth = {"Authorization": "Bearer " + (data / "api_token").read_text().strip()}
    client = httpx.Client(base_url=f"http://127.0.0.1:{process.port}", timeout=SYNC_BOUND_S)
    load = job = None
    try:
        body = {"url": robot.url, "tracker_port": free_port(socket.SOCK_DGRAM)}
        connected = client.post("/api/v1/robot/connect", json=body, headers=auth)
        assert connected.status_code == 200 and connected.json()["state"] == "disarmed", connected.text
        job = client.post("/api/v1/jobs", json=HEAVY_JOB, headers=auth).json()["id"]
        deadline = time.monotonic() + JOB_START_S
        while client.get(f"/api/v1/jobs/{job}").json()["completed"] == 0:  # its kernels are loaded
            assert time.monotonic() < deadline, f"the job's first chunk within {JOB_START_S:g} s"
            time.sleep(0.05)
        load = start_map_load(str(client.base_url))
        yield client, auth, robot, job
        assert client.get(f"/api/v1/jobs/{job}").json()["state"] == "running", "the job ran throughout"
    finally:
        answered = stop_map_load(load) if load is not None else {}
        if job is not None:
            client.post(f"/api/v1/jobs/{job}/cancel", headers=auth)
        client.post("/api/v1/robot/reset", headers=auth)
        client.post("/api/v1/robot/disconnect", headers=auth)
        client.close()
        robot.stop()
        process.terminate()
        try:
            process.wait(30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    assert set(answered) == {"200"} and answered["200"] >= 10, f"the computations were real: {answered}"


def _press(client) -> tuple[float, dict]:
    started = time.perf_counter()
    response = client.post("/api/v1/robot/estop", timeout=ESTOP_BOUND_S * 5)  # no token
    assert response.status_code == 200, response.text
    return started, response.json() | {"http_ms": (time.perf_counter() - started) * 1e3}


@pytest.mark.slow
def test_estop_is_acknowledged_while_a_job_and_45_clients_saturate_the_service(saturated):
    client, auth, robot, _job = saturated
    presses = []
    for _ in range(PRESSES):
        assert client.post("/api/v1/robot/arm", headers=auth).json()["state"] == "armed"
        _started, stopped = _press(client)
        presses.append({"http_ms": round(stopped["http_ms"]), "ack_ms": round(stopped["latency_ms"], 1)})
        assert stopped["acknowledged"] is True, (stopped.get("reason"), presses)
        assert stopped["state"] == "estopped" and robot.firmware.state.name == "ESTOPPED", stopped
        assert stopped["http_ms"] < ESTOP_BOUND_S * 1e3, f"an e-stop took over {ESTOP_BOUND_S:g} s: {presses}"
        assert client.post("/api/v1/robot/reset", headers=auth).json()["state"] == "disarmed"
    print(f"e-stop under load: {presses}")


@pytest.mark.slow
def test_every_estop_is_acknowledged_while_the_service_is_saturated(saturated):
    """50 presses while the job computes and 45 clients call /sim/map: each one acknowledged by the
    robot within the link's own 150 ms budget. (Before compute moved to worker processes, 2 in 100
    were not, and round trips reached 642 ms: scripts/bench_estop_api.py measures them.)"""
    client, _auth, robot, _job = saturated
    presses = []
    for _ in range(PROMISE_PRESSES):  # a latched robot acknowledges each press all the same
        robot.firmware.estops.clear()
        started, stopped = _press(client)
        reached = (robot.firmware.estops[0] - started) * 1e3 if robot.firmware.estops else None
        presses.append(
            (round(stopped["http_ms"]), None if reached is None else round(reached), stopped["acknowledged"])
        )
    missed = [press for press in presses if not press[2] or press[0] > ESTOP_BOUND_S * 1e3]
    assert missed == [], f"(round trip ms, press to robot ms, acknowledged), unacknowledged or slow: {presses}"
    print(f"e-stop under load, {PROMISE_PRESSES} presses: {presses}")
