"""One operator per run: while a live run goes on, the link is not changed under it (409 naming the
run); a connect that fails leaves the working link as it was; a tracker port in use is a 409."""

import socket
import time

import pytest

from tests.helpers import free_port

CONTROLS = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]
LAUNCH_WITHIN_S = 10.0  # a hang guard: the robot running after a run starts, not a timing assertion


@pytest.fixture
def database_url():
    return None  # SQLite: these are tests of the robot path


@pytest.fixture
def connected(client, auth, virtual):
    """``(robot, connect body)``: the virtual robot, connected."""
    robot, port = virtual
    body = {"url": robot.url, "tracker_port": port}
    response = client.post("/api/v1/robot/connect", json=body, headers=auth)
    assert response.status_code == 200, response.text
    yield robot, body
    client.post("/api/v1/robot/runs/stop", headers=auth)
    client.post("/api/v1/robot/disconnect", headers=auth)


def test_link_changes_during_a_run_are_refused_naming_it(client, auth, connected):
    _robot, body = connected
    started = client.post(
        "/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 200, "operator": "Ada"}, headers=auth
    )
    assert started.status_code == 202, started.text
    run = started.json()["run"]
    assert run["started_by"] == "lab (operator: Ada)" and run["active"], "the token's person, and who is at the table"
    bad_url = {**body, "url": "socket://127.0.0.1:1"}
    calls = (("connect", body), ("connect", bad_url), ("disconnect", None), ("arm", None), ("reset", None))
    for call, json in (*calls, ("runs", {"controls": CONTROLS})):
        refused = client.post(f"/api/v1/robot/{call}", json=json, headers=auth)
        detail = refused.json()["detail"]
        assert (
            refused.status_code == 409 and f"live run {run['id']}" in detail and "by lab (operator: Ada)" in detail
        ), (call, detail)
    # The run goes on, untouched: it launches the robot (armed, running once the robot says so:
    # a loaded machine answered the six refusals before that, once) and is still going.
    deadline = time.monotonic() + LAUNCH_WITHIN_S
    while (status := client.get("/api/v1/robot").json())["state"] != "running" and time.monotonic() < deadline:
        assert status["run"]["active"] and status["state"] in ("disarmed", "armed"), status["state"]
        time.sleep(0.02)
    assert status["run"]["active"] and status["state"] == "running", "the run goes on, untouched"
    stopped = client.post("/api/v1/robot/runs/stop", headers=auth).json()  # stopping is always allowed
    assert stopped["run"]["end_reason"] == "stopped"
    assert client.post("/api/v1/robot/disconnect", headers=auth).status_code == 200


def test_a_run_started_without_an_operator_names_the_tokens_person(client, auth, connected, settings):
    from backend.store.people import PeopleFile

    ada = {"Authorization": f"Bearer {PeopleFile(settings.data_dir).add('ada')}"}
    run = client.post("/api/v1/robot/runs", json={"controls": CONTROLS, "jumps": 200, "operator": "ada"},
                      headers=ada).json()["run"]  # fmt: skip
    assert run["started_by"] == "ada", "an operator who is the person is said once"
    stored = client.get(f"/api/v1/runs/{run['id']}").json()
    assert stored["results"]["started_by"] == "ada" and stored["created_by"] == "ada"


def test_a_connect_that_fails_leaves_the_working_link(client, auth, connected):
    robot, body = connected
    before = client.get("/api/v1/robot").json()
    failed = client.post("/api/v1/robot/connect", json={**body, "url": "socket://127.0.0.1:1"}, headers=auth)
    assert failed.status_code == 503 and "cannot open socket://127.0.0.1:1" in failed.json()["detail"]
    after = client.get("/api/v1/robot").json()
    assert (after["state"], after["url"]) == ("disarmed", robot.url), "still connected to the working robot"
    assert after["counters"]["reconnects"] == before["counters"]["reconnects"], "never dropped"
    assert after["tracker"]["address"] == before["tracker"]["address"]
    assert client.post("/api/v1/robot/arm", headers=auth).status_code == 200


def test_a_tracker_port_in_use_is_a_409_naming_it(client, auth, connected):
    _robot, body = connected
    taken = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    taken.bind(("127.0.0.1", 0))
    try:
        port = taken.getsockname()[1]
        response = client.post("/api/v1/robot/connect", json={**body, "tracker_port": port}, headers=auth)
        assert response.status_code == 409, response.text
        assert f"tracker_port {port}" in response.json()["detail"] and "in use" in response.json()["detail"]
    finally:
        taken.close()
    status = client.get("/api/v1/robot").json()
    assert (status["state"], status["tracker"]["address"][1]) == ("disarmed", body["tracker_port"])


def test_connecting_again_on_its_own_tracker_port_works(client, auth, connected):
    _robot, body = connected
    again = client.post("/api/v1/robot/connect", json=body, headers=auth)
    assert again.status_code == 200 and again.json()["tracker"]["address"][1] == body["tracker_port"], again.text


def test_a_tracker_address_this_machine_cannot_bind_is_a_422(client, auth, connected):
    _robot, body = connected
    bad = {**body, "tracker_host": "192.0.2.1", "tracker_port": free_port(socket.SOCK_DGRAM)}  # TEST-NET: not ours
    response = client.post("/api/v1/robot/connect", json=bad, headers=auth)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "tracker_host"]


def test_stopping_with_no_live_run_is_no_error(client, auth):
    """Stopping is always possible: with nothing to stop, the status as it is (it was a 404 naming "live run 0")."""
    for _ in range(2):
        response = client.post("/api/v1/robot/runs/stop", headers=auth)
        assert response.status_code == 200 and response.json()["run"] is None
