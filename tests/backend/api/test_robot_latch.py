"""The e-stop latch through the API: it holds across a lost link, an automatic reconnect, a connect
by hand and a service restart, until a RESET is acknowledged (issue 24's reproduction).

The robot is on a socket line of its own (``PtyRobot(line="socket")``), not a pty: a ``/dev/pts/N``
may be opened by another program on the machine (issue 40: a restart test beside another service's
pty robot heard no telemetry), and nothing here is about serial devices.
"""

import time

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.robot.messages import Kind, RobotState
from tests.robot_rig import PtyRobot, wait_for

LOST_ON_THE_AIR = 0x21  # a Transmit Status: network ACK failure (the robot's radio did not take it)
DELIVERED = 0x00
SILENCE_S = 1.6  # [s] the robot out of range: longer than the link's 1 s heartbeat timeout
ESTOP_REPEATS = 3  # the link's ESTOPs in a row, in place of heartbeats: more than one heartbeat period's worth


@pytest.fixture
def database_url():
    return None  # SQLite: nothing here depends on the database


@pytest.fixture
def deaf_robot():
    """An armed robot behind a pty whose radio talks but loses every frame the PC sends."""
    rig = PtyRobot(RobotState.ARMED, answers=True, line="socket").start()
    yield rig
    rig.stop()


def _connect(client, auth, rig) -> dict:
    body = {"url": rig.url, "tracker_port": 0}  # no tracker here: any free port, bound by the service
    response = client.post("/api/v1/robot/connect", json=body, headers=auth)
    assert response.status_code == 200, response.text
    return response.json()


def _kinds_since(rig, since: int) -> list[Kind]:
    return [getattr(message, "kind", None) for message in rig.sent[since:]]


def _estops_sent(rig, since: int) -> list[Kind]:
    """What the PC sent from ``since`` on, once it has sent ESTOP_REPEATS ESTOPs: counted in frames,
    not timed, so a loaded machine only makes the wait longer."""
    wait_for(lambda: _kinds_since(rig, since).count(Kind.ESTOP) >= ESTOP_REPEATS, f"{ESTOP_REPEATS} ESTOPs sent")
    return _kinds_since(rig, since)


def test_an_unacknowledged_estop_holds_across_an_automatic_reconnect(client, auth, deaf_robot):
    rig = deaf_robot
    assert _connect(client, auth, rig)["state"] == "armed"
    rig.delivery_status = LOST_ON_THE_AIR
    stopped = client.post("/api/v1/robot/estop").json()
    assert stopped["acknowledged"] is False and stopped["estop"]["latched"] is True

    rig.go_silent()  # out of range: the link is lost, and the supervisor reconnects by itself
    wait_for(lambda: client.get("/api/v1/robot").json()["state"] == "disconnected", "the link lost")
    time.sleep(SILENCE_S - 1.0)
    rig.resume()
    wait_for(lambda: client.get("/api/v1/robot").json()["counters"]["reconnects"] >= 1, "reconnected")

    status = client.get("/api/v1/robot").json()
    assert status["estop"]["latched"] is True and status["estop"]["acknowledged"] is False, status["estop"]
    sent = _estops_sent(rig, len(rig.sent))
    assert Kind.HEARTBEAT not in sent, f"the latched ESTOP in place of heartbeats: {sent}"
    arm = client.post("/api/v1/robot/arm", headers=auth)
    assert arm.status_code == 409 and "latch holds" in arm.json()["detail"], arm.text
    run = client.post("/api/v1/robot/runs", json={"controls": [{"psi0_deg": 30, "zeta0": 0.9}] * 2}, headers=auth)
    assert run.status_code == 409 and "latch holds" in run.json()["detail"], run.text
    assert rig.state == RobotState.ARMED, "nothing reached the robot yet; its own watchdog is what stops it"

    rig.delivery_status = DELIVERED  # the air clears: the stop is delivered, the latch still holds
    wait_for(lambda: client.get("/api/v1/robot").json()["state"] == "estopped", "the robot e-stopped")
    assert rig.state == RobotState.ESTOPPED
    latch = client.get("/api/v1/robot").json()["estop"]
    assert latch["latched"] is True and latch["acknowledged"] is True
    assert client.post("/api/v1/robot/arm", headers=auth).status_code == 409
    assert client.post("/api/v1/robot/reset", headers=auth).status_code == 200
    assert client.get("/api/v1/robot").json()["estop"]["latched"] is False
    assert client.post("/api/v1/robot/arm", headers=auth).status_code == 200


def test_a_held_latch_survives_a_connect_by_hand_and_a_service_restart(settings, compute, client, auth, deaf_robot):
    rig = deaf_robot
    _connect(client, auth, rig)
    rig.delivery_status = LOST_ON_THE_AIR
    assert client.post("/api/v1/robot/estop").json()["acknowledged"] is False
    _connect(client, auth, rig)  # by hand, while the robot still hears nothing
    assert client.get("/api/v1/robot").json()["estop"]["latched"] is True
    assert client.post("/api/v1/robot/arm", headers=auth).status_code == 409
    client.post("/api/v1/robot/disconnect", headers=auth)

    with TestClient(create_app(settings, compute=compute)) as restarted:  # the same data directory
        assert restarted.get("/api/v1/robot").json()["estop"]["latched"] is True
        since = len(rig.sent)
        _connect(restarted, auth, rig)
        sent = _estops_sent(rig, since)
        assert sent[0] == Kind.ESTOP and set(sent) <= {Kind.ESTOP, Kind.DISARM}, (
            f"the ESTOP first, never a heartbeat: {sent}"
        )
        assert restarted.post("/api/v1/robot/arm", headers=auth).status_code == 409
        rig.delivery_status = DELIVERED
        wait_for(lambda: restarted.get("/api/v1/robot").json()["state"] == "estopped", "the robot e-stopped")
        assert restarted.post("/api/v1/robot/reset", headers=auth).status_code == 200
        assert restarted.get("/api/v1/robot").json()["estop"]["latched"] is False
        restarted.post("/api/v1/robot/disconnect", headers=auth)
