"""The robot's routes (backend/api/routes/robot.py) against the virtual robot: the token for every call
but the e-stop, live runs recorded like simulated runs and safe to stop, the live view's stream."""

import math
import threading
import time

import pytest
from starlette.websockets import WebSocketDisconnect

from backend.api.app import REQUEST_THREADS
from backend.robot.messages import RobotState
from backend.robot.virtual import VirtualRobot
from tests.helpers import answer_within
from tests.robot_rig import PtyRobot

POOL_THREADS = REQUEST_THREADS  # the request thread pool's
POOL_FILLERS = 45  # more than the request thread pool's threads
ANSWER_BOUND_S = 2.0  # [s] "answers instead of hanging": generous, not a latency claim

CONTROLS = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]


@pytest.fixture
def database_url():
    """SQLite only: these are tests of the robot path; what it stores goes through the run
    repository (backend/repositories/runs.py), which every store and API test of runs checks on both
    databases. Running them twice cost CI about 25 s of real-time robot runs."""
    return None


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
    for call in ("arm", "disarm", "reset", "disconnect", "runs/stop"):
        assert client.post(f"/api/v1/robot/{call}").status_code == 401, call
    assert client.post("/api/v1/robot/runs", json={"controls": CONTROLS}).status_code == 401
    assert client.get("/api/v1/robot").json()["state"] == "disconnected"


def test_estop_needs_no_token_and_reaches_the_robot(client, auth, connected, patient_estop):
    client.post("/api/v1/robot/arm", headers=auth)
    response = client.post("/api/v1/robot/estop")  # no token: stopping is always allowed
    assert response.status_code == 200, response.text
    stopped = response.json()
    assert stopped["acknowledged"] is True and "reason" not in stopped and stopped["latency_ms"] >= 0
    assert stopped["state"] == "estopped" and connected.firmware.state.name == "ESTOPPED"
    assert client.post("/api/v1/robot/reset").status_code == 401, "releasing it needs the token"
    assert client.get("/api/v1/robot").json()["estop"]["pressed_by"] == "someone at testclient"
    released = client.post("/api/v1/robot/reset", headers=auth).json()["estop"]
    assert not released["latched"] and released["reset_by"] == "lab" and released["reset_at"] > 0


def test_estop_answers_while_the_request_pool_is_full(client, auth, connected, monkeypatch, patient_estop):
    """45 stored-run requests hold every request thread (each waits inside the route, storing its
    run): the e-stop, async and on its own thread, answers all the same. Real compute under load:
    test_estop_load.py."""
    from backend.services import runs

    release, entered = threading.Event(), threading.Semaphore(0)
    store_run = runs.store_run

    def held(*args, **kwargs):
        entered.release()
        release.wait(60)
        return store_run(*args, **kwargs)

    monkeypatch.setattr(runs, "store_run", held)
    body = {"controls": CONTROLS[:1], "start": {"xdot": -0.9, "ydot": -0.2}, "jumps": 3}
    answers = []

    def store():
        answers.append(client.post("/api/v1/runs", json=body, headers=auth).status_code)

    callers = [threading.Thread(target=store, daemon=True) for _ in range(POOL_FILLERS)]
    for caller in callers:
        caller.start()
    try:
        for _ in range(POOL_THREADS):  # every request thread is inside the route
            assert entered.acquire(timeout=ANSWER_BOUND_S * 10), "the request pool did not fill"
        stopped = answer_within(ANSWER_BOUND_S, client.post, "/api/v1/robot/estop").json()
    finally:
        release.set()
    assert stopped["acknowledged"] is True and stopped["state"] == "estopped", stopped.get("reason")
    for caller in callers:
        caller.join(60)
    assert answers == [201] * POOL_FILLERS, "the requests were real, and held the pool"


def test_estop_without_a_robot_says_so(client):
    stopped = client.post("/api/v1/robot/estop").json()
    assert stopped["acknowledged"] is False and stopped["reason"].startswith("the robot is not connected")
    assert stopped["estop"]["latched"] is True and stopped["estop"]["durable"] is True, "it latches all the same"


def test_estop_on_a_jammed_line_answers_without_hanging(client, auth):
    rig = PtyRobot(RobotState.ARMED).start()
    try:
        body = {"url": rig.path, "tracker_port": 0}  # a pty, as socat gives one; no tracker: any free port
        response = client.post("/api/v1/robot/connect", json=body, headers=auth)
        assert response.status_code == 200 and response.json()["state"] == "armed", response.text
        rig.jam()
        response = answer_within(ANSWER_BOUND_S, client.post, "/api/v1/robot/estop")
        stopped = response.json()
        assert response.status_code == 200 and stopped["acknowledged"] is False, stopped
        assert "no acknowledgement" in stopped["reason"] and stopped["state"] == "armed"
        counters = client.get("/api/v1/robot").json()["counters"]
        assert counters["write_timeouts"] >= 1 and counters["estops_unacknowledged"] == 1
        arm = client.post("/api/v1/robot/arm", headers=auth)
        assert arm.status_code == 409 and "latch holds" in arm.text and "reset" in arm.text, arm.text
    finally:
        client.post("/api/v1/robot/disconnect", headers=auth)
        rig.stop()


def test_status_shows_the_robot_address_and_the_links_counters(client, connected):
    status = client.get("/api/v1/robot").json()
    assert status["robot_address"] == "0x0013A20040B0B0B0"
    counters = status["counters"]
    assert counters["frames_in"] > 0
    for name in ("bad_checksum", "garbage_bytes", "rejected_payloads", "foreign_frames", "write_timeouts"):
        assert counters[name] == 0, name


def test_a_link_to_another_robot_address_hears_nothing(client, auth, virtual):
    robot, port = virtual
    body = {"url": robot.url, "tracker_port": port, "robot_address": "0013A200DEADBEEF"}
    response = client.post("/api/v1/robot/connect", json=body, headers=auth)
    assert response.status_code == 503 and "no telemetry" in response.text
    body["robot_address"] = "0x12"
    response = client.post("/api/v1/robot/connect", json=body, headers=auth)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "robot_address"]


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
    trajectory = client.get(f"/api/v1/runs/{run['id']}/trajectory").json()
    assert len(trajectory["columns"]["time"]) > 100, "raw tracker frames are kept"
    assert trajectory["units"] == "SI" and trajectory["column_units"] == {
        "time": "s",
        "x": "m",
        "y": "m",
        "pitch": "rad",
    }
    tracker = results["tracker"]
    assert tracker["received"] == tracker["frames"] and (tracker["protocol"], tracker["version"]) == ("pkt1", "1")
    assert results["link"]["url"] == connected.url and results["started_by"] == "lab"


def test_a_live_run_is_filed_under_its_experiment_and_a_missing_one_moves_nothing(client, auth, connected):
    body = {"controls": CONTROLS, "jumps": 2, "experiment_id": 999}
    missing = client.post("/api/v1/robot/runs", json=body, headers=auth)
    assert missing.status_code == 404 and "experiment 999" in missing.json()["detail"]
    assert client.get("/api/v1/robot").json()["state"] == "disarmed", "nothing was armed for it"
    experiment = client.post("/api/v1/experiments", json={"name": "live"}, headers=auth).json()["id"]
    body["experiment_id"] = experiment
    assert client.post("/api/v1/robot/runs", json=body, headers=auth).status_code == 202
    status = _finish(client)
    assert client.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()["experiment_id"] == experiment


def test_estop_during_a_run_ends_it_and_keeps_the_data(client, auth, connected, patient_estop):
    client.post("/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 1000}, headers=auth)
    _wait_for_touchdowns(client, 3)
    stopped = client.post("/api/v1/robot/estop").json()
    assert stopped["acknowledged"] is True and stopped["state"] == "estopped"
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
@pytest.mark.robot_speed(1.0)
@pytest.mark.realtime
@pytest.mark.parametrize("controller", ["pid", "lqr", "deadbeat"])
def test_closed_loop_live_run_holds_a_height(client, auth, connected, controller):
    loop = {"target_m": 0.4} | ({} if controller == "pid" else {"controller": controller})
    body = {"controls": [{"psi0_deg": 35, "zeta0": 0.9}] * 2, "jumps": 25, "closed_loop": loop}
    client.post("/api/v1/robot/runs", json=body, headers=auth)
    status = _finish(client, timeout=90)
    run = client.get(f"/api/v1/runs/{status['run']['stored_run_id']}").json()
    results = run["results"]
    heights = [td["body_height"] for td in results["touchdowns"]]
    # Once (a CI run, 2026-12-06) pid's run ended after one touchdown, why unrecorded: say it if again.
    assert results.get("end_reason") == "jumps done" and len(heights) == 25, (results.get("end_reason"), heights)
    # The robot answers in real time, so when each command lands differs from run to run (by up to
    # 0.035 m in a jump of a loaded CI machine): the loop must close the gap, not trace one path.
    errors = [abs(h - 0.4) for h in heights]
    assert errors[0] > 0.15 and errors[-1] < 0.025, heights
    assert sum(errors[-8:]) / 8 < 0.025 and max(errors[-8:]) < 0.05, heights
    laws = [c for c in results["commands"] if c["why"].startswith(f"{controller} after touchdown")]
    assert len(laws) >= 20 and all(c["controller"] == controller and len(c["state"]) == 2 for c in laws)
    assert (run["controller"], run["target"], results["closed_loop"]["controller"]) == (controller, 0.4, controller)
    if controller == "lqr":  # it commands the leg angle too, within the servos' range
        assert len({round(c["psi0_deg"], 6) for c in laws}) > 1 and all(10 <= c["psi0_deg"] <= 60 for c in laws)


@pytest.mark.parametrize(
    ("change", "loc", "says"),
    [
        (
            {"controller": "mpc"},
            ["body", "closed_loop", "controller"],
            "must be one of pid, pid-pitch, lqr, deadbeat, placement",
        ),
        ({"target_m": 2.5}, ["body", "closed_loop", "target_m"], "less than or equal to 2"),
        ({"target_m": 0.0}, ["body", "closed_loop", "target_m"], "greater than 0"),
        ({"zeta0_min": 0.7}, ["body", "closed_loop.zeta0_min"], "must be in [0.75, 0.98]"),
        ({"kp": 11}, ["body", "closed_loop", "kp"], "less than or equal to 10"),
        ({"preset": "no-such-table"}, ["body", "closed_loop.preset"], "unknown preset 'no-such-table'; known presets"),
    ],
)
def test_a_closed_loop_it_cannot_run_is_a_422_naming_the_field(client, auth, connected, change, loc, says):
    body = {"controls": CONTROLS, "jumps": 5, "closed_loop": {"target_m": 0.4, "controller": "lqr"} | change}
    response = client.post("/api/v1/robot/runs", json=body, headers=auth)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"][0]
    assert detail["loc"] == loc and says in detail["msg"], detail
    assert connected.firmware.state.name == "DISARMED" and client.get("/api/v1/robot").json()["run"] is None


@pytest.mark.parametrize("url", ["/dev/sda", "/dev/watchdog", "/dev/null", "http://robot", "socket://a b:1"])
def test_only_serial_ports_and_robot_sockets_can_be_opened(client, auth, url):
    response = client.post("/api/v1/robot/connect", json={"url": url}, headers=auth)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "url"]


@pytest.mark.parametrize(("name", "why"), [("ttyUSB0", "is not a character device"), ("ttyUSB97", "does not exist")])
def test_a_device_path_that_is_not_a_device_is_a_422_naming_it(client, auth, tmp_path, name, why):
    (tmp_path / "ttyUSB0").write_bytes(b"")  # a regular file: never opened
    path = str(tmp_path / name)
    response = client.post("/api/v1/robot/connect", json={"url": path}, headers=auth)
    assert response.status_code == 422
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "url"] and f"{path} {why}" in detail["msg"]


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


@pytest.mark.parametrize("rate", ["0", "51", "nan", "fast"])
def test_the_live_views_rate_is_bounded(client, rate):
    with pytest.raises(WebSocketDisconnect), client.websocket_connect(f"/api/v1/robot/live?rate={rate}") as live:
        live.receive_json()


def test_the_live_view_streams_without_a_robot(client):
    with client.websocket_connect("/api/v1/robot/live?rate=50") as live:
        first, second = live.receive_json(), live.receive_json()
    assert first["state"] == second["state"] == "disconnected" and first["tracker"] is None


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


@pytest.mark.robot_speed(1.0)
@pytest.mark.realtime  # a closed loop answers each touchdown within the next stance
def test_a_closed_loop_designed_on_a_stored_calibration_takes_its_leg_offsets_off(client, auth, connected):
    """closed_loop.preset names a calibration: the LQR is designed on its fitted model and each
    command is the law's less the fitted offset of its leg; the stored run names the preset."""
    from backend.robot.limits import ServoLimits
    from backend.robot.live_law import live_law_for
    from backend.schemas import ClosedLoopIn
    from backend.services.presets import resolve_model
    from sim_core.model.controls import LegControl
    from sim_core.model.noise import NoiseModel
    from tests.tracked_climbs import Truth, store_varied_runs

    truth = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
    with client.app.state.sessions() as session:
        runs = store_varied_runs(session, truth, noise=NoiseModel(), jumps=30)
    assert client.post("/api/v1/calibrations", json={"runs": runs, "name": "table"}, headers=auth).status_code == 201
    loop = {"target_m": 0.4, "controller": "lqr", "preset": "table"}
    body = {"controls": [{"psi0_deg": 35, "zeta0": 0.9}] * 2, "jumps": 6, "closed_loop": loop}
    assert client.post("/api/v1/robot/runs", json=body, headers=auth).status_code == 202
    run = client.get(f"/api/v1/runs/{_finish(client)['run']['stored_run_id']}").json()
    assert run["results"]["closed_loop"]["preset"] == "table" and run["controller"] == "lqr"
    laws = [c for c in run["results"]["commands"] if c["why"].startswith("lqr after touchdown")]
    assert len(laws) >= 4
    # The same law stepped on the same touchdowns, offline: the service designed it on the calibration.
    with client.app.state.sessions() as session:
        design = resolve_model(session, "table")
    legs = [LegControl.from_degrees(35, 0.9)] * 2
    twin = live_law_for(ClosedLoopIn(**loop), design.robot, legs, ServoLimits(), offsets=design.offsets)
    from backend.robot.touchdown import Touchdown

    for command, stored in zip(laws, run["results"]["touchdowns"], strict=False):
        touchdown = Touchdown.from_dict({key: stored[key] for key in Touchdown.__dataclass_fields__})
        control, _ = twin.command(touchdown, math.nan, 0.0)
        assert command["psi0_deg"] == pytest.approx(control.psi0_deg, abs=1e-9)
        assert command["zeta0"] == pytest.approx(control.zeta0, abs=1e-12)


@pytest.mark.parametrize(("value", "says"), [(10, "greater than or equal to 30"), (1000, "less than or equal to 250")])
def test_a_tracker_timeout_outside_its_safe_range_is_a_422_naming_it(client, auth, connected, value, says):
    body = {"controls": CONTROLS, "jumps": 5, "tracker_timeout_ms": value}
    response = client.post("/api/v1/robot/runs", json=body, headers=auth)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"][0]
    assert detail["loc"] == ["body", "tracker_timeout_ms"] and says in detail["msg"], detail
    assert connected.firmware.state.name == "DISARMED" and client.get("/api/v1/robot").json()["run"] is None
