"""Live runs through the API against the virtual robot: recorded like simulated runs, safe to stop."""

import time

import pytest

from backend.robot.virtual import VirtualRobot

CONTROLS = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]


@pytest.fixture
def connected(client, auth, virtual):
    robot, port = virtual
    body = {"url": robot.url, "tracker_port": port}
    response = client.post("/api/v1/robot/connect", json=body, headers=auth)
    assert response.status_code == 200, response.text
    assert response.json()["state"] == "disarmed"
    yield robot
    client.post("/api/v1/robot/disconnect", headers=auth)


def _wait_for_touchdowns(client, count: int, timeout=20.0) -> None:
    deadline = time.monotonic() + timeout
    while client.get("/api/v1/robot").json()["run"]["touchdowns"] < count:
        assert time.monotonic() < deadline, f"fewer than {count} touchdowns after {timeout} s"
        time.sleep(0.02)


def _finish(client, timeout=30.0):
    deadline = time.monotonic() + timeout
    while (status := client.get("/api/v1/robot").json())["run"]["active"]:
        assert time.monotonic() < deadline, status
        time.sleep(0.05)
    return status


def test_robot_calls_need_the_token(client, virtual):
    robot, port = virtual
    assert client.post("/api/v1/robot/connect", json={"url": robot.url, "tracker_port": port}).status_code == 401
    assert client.post("/api/v1/robot/estop").status_code == 401
    assert client.get("/api/v1/robot").json()["state"] == "disconnected"


def test_open_loop_live_run_is_stored_with_the_model_beside_it(client, auth, connected):
    response = client.post(
        "/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 8, "tags": ["live"]}, headers=auth
    )
    assert response.status_code == 202, response.text
    status = _finish(client)
    assert status["run"]["end_reason"] == "jumps done" and status["state"] == "disarmed"
    run = client.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()
    assert run["kind"] == "robot" and run["status"] == "done" and run["tags"] == ["live"]
    results = run["results"]
    assert len(results["touchdowns"]) == 8 and all(gain > 0 for gain in results["rises"])
    predicted, measured = results["prediction"]["states"], results["states"]
    assert (
        max(abs(p - m) for pair in zip(predicted[1:], measured[1:], strict=True) for p, m in zip(*pair, strict=True))
        < 0.1
    )
    assert [c["why"] for c in results["commands"]] == ["start", "start"]
    assert results["calibration"] == {"origin": [0.0, 0.0], "angle": 0.0, "scale": 1.0}
    frames = client.get(f"/api/v1/runs/{run['id']}/trajectory").json()["columns"]
    assert len(frames["time"]) > 100, "raw tracker frames are kept"


def test_estop_during_a_run_ends_it_and_keeps_the_data(client, auth, connected):
    client.post("/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 1000}, headers=auth)
    _wait_for_touchdowns(client, 3)
    stopped = client.post("/api/v1/robot/estop", headers=auth).json()
    assert stopped["state"] == "estopped" and stopped["latency_ms"] < 100
    status = _finish(client)
    assert status["run"]["end_reason"] == "e-stop"
    run = client.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()
    assert run["status"] == "failed" and len(run["results"]["touchdowns"]) >= 3
    assert client.post("/api/v1/robot/runs", json={"controls": CONTROLS}, headers=auth).status_code == 409
    client.post("/api/v1/robot/reset", headers=auth)
    assert client.get("/api/v1/robot").json()["state"] == "disarmed"


def test_losing_the_robot_aborts_the_run_with_the_data_kept(client, auth, connected):
    client.post("/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 1000}, headers=auth)
    _wait_for_touchdowns(client, 2)
    connected.stop()  # the robot goes silent
    status = _finish(client)
    assert status["run"]["end_reason"] == "link lost" and status["state"] == "disconnected"
    run = client.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()
    assert len(run["results"]["touchdowns"]) >= 2 and run["results"]["transitions"][-1]["to"] == "disconnected"


def test_commands_beyond_the_servo_limits_are_a_422(client, auth, connected):
    bad = [{"psi0_deg": 30, "zeta0": 0.99}, CONTROLS[1]]
    response = client.post("/api/v1/robot/runs", json={"controls": bad}, headers=auth)
    assert response.status_code == 422 and "zeta0" in response.text
    assert connected.firmware.state.name == "DISARMED"


@pytest.mark.slow
def test_closed_loop_live_run_holds_a_height(client, auth, connected):
    body = {"controls": [{"psi0_deg": 35, "zeta0": 0.9}] * 2, "jumps": 45, "closed_loop": {"target_m": 0.4}}
    client.post("/api/v1/robot/runs", json=body, headers=auth)
    status = _finish(client, timeout=60)
    results = client.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()["results"]
    heights = [td["body_height"] for td in results["touchdowns"]]
    assert abs(heights[-1] - 0.4) < 0.02 and max(abs(h - 0.4) for h in heights[-8:]) < 0.03, heights
    assert sum(c["why"].startswith("pid") for c in results["commands"]) >= 40


@pytest.mark.parametrize("url", ["/dev/sda", "/dev/watchdog", "http://robot", "socket://a b:1"])
def test_only_serial_ports_and_robot_sockets_can_be_opened(client, auth, url):
    response = client.post("/api/v1/robot/connect", json={"url": url}, headers=auth)
    assert response.status_code == 422 and "url" in response.text


def test_live_state_streams_over_websocket(client, auth, connected):
    client.post("/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 6}, headers=auth)
    heights, touchdowns = [], 0
    with client.websocket_connect("/api/v1/robot/live?rate=50") as live:
        for _ in range(200):
            message = live.receive_json()
            pose = message["tracker"]["latest"] if message["tracker"] else None
            if pose is not None:
                heights.append(pose["y"])
            touchdowns = max(touchdowns, len(message["recent_touchdowns"]))
            if message["run"] and not message["run"]["active"]:
                break
    assert len(heights) > 20 and max(heights) > min(heights) + 0.2, "the body climbs on the live view"
    assert touchdowns >= 3
    _finish(client)


def test_the_link_comes_back_after_the_robot_restarts(client, auth, connected):
    host, port = connected.address
    connected.stop()
    deadline = time.monotonic() + 10
    while client.get("/api/v1/robot").json()["state"] != "disconnected":
        assert time.monotonic() < deadline
        time.sleep(0.05)
    restarted = VirtualRobot(host, port).start()  # same address: the robot rebooted
    try:
        deadline = time.monotonic() + 10
        while (status := client.get("/api/v1/robot").json())["state"] != "disarmed":
            assert time.monotonic() < deadline, status
            time.sleep(0.05)
        reasons = [t["reason"] for t in status["transitions"]]
        assert any("heartbeat" in r or "read failed" in r for r in reasons) and reasons[-1] == "telemetry"
        assert client.post("/api/v1/robot/arm", headers=auth).json()["state"] == "armed"
    finally:
        client.post("/api/v1/robot/disconnect", headers=auth)
        restarted.stop()


def test_a_recorded_run_replays_to_the_same_touchdowns(client, auth, connected):
    client.post("/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 6}, headers=auth)
    live_id = _finish(client)["run"]["stored_run_id"]
    replay = client.post(f"/api/v1/runs/{live_id}/replay", headers=auth)
    assert replay.status_code == 201, replay.text
    replayed, live = replay.json(), client.get(f"/api/v1/runs/{live_id}").json()
    assert replayed["kind"] == "replay" and replayed["results"]["source_run_id"] == live_id
    assert replayed["results"]["states"][:6] == live["results"]["states"][:6]
    assert "replay" in replayed["tags"]
    simulated = client.post("/api/v1/runs", json={"controls": CONTROLS[:1], "start": {"xdot": -0.9, "ydot": -0.2}},
                            headers=auth).json()  # fmt: skip
    assert client.post(f"/api/v1/runs/{simulated['id']}/replay", headers=auth).status_code == 409
