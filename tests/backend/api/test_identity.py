"""Named people (backend/api/identity.py, issue 40): each person's token signs them in; what they do
is recorded under their name, whatever header their tool sends; a read-only token changes nothing;
a revoked one is refused at its next request; a service that listens beyond its machine asks a
token of every read, and the panel's cookie counts for reads only."""

from __future__ import annotations

import dataclasses

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from backend.api.app import create_app
from backend.store.people import Access, PeopleFile

CONTROLS = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]
RUN = {"start": {"xdot": -0.93, "ydot": -0.17}, "controls": CONTROLS, "jumps": 3}


@pytest.fixture
def database_url():
    return None  # SQLite: who did what is the same on either store (tests/backend/store covers the columns)


@pytest.fixture
def people(settings):
    return PeopleFile(settings.data_dir)


def bearer(token: str) -> dict:
    return {"Authorization": f"Bearer {token}"}


def test_what_a_person_does_is_recorded_under_their_name(client, people):
    ada = bearer(people.add("ada"))
    assert client.get("/api/v1/auth", headers=ada).json() == {"accepted": True, "name": "ada", "access": "write"}
    run = client.post("/api/v1/runs", json=RUN, headers=ada)
    assert run.status_code == 201, run.text
    assert run.json()["created_by"] == "ada" and run.json()["notes_by"] is None
    noted = client.patch(f"/api/v1/runs/{run.json()['id']}", json={"notes": "slipped twice"}, headers=ada).json()
    assert noted["notes_by"] == "ada"
    listed = client.get("/api/v1/runs").json()["items"][0]
    assert (listed["created_by"], listed["notes_by"]) == ("ada", "ada"), "the History list shows it too"
    body = {"zeta0s": [0.9], "trials": 2, "cap": 20}
    for tool in ("panel", "ada-script", None):
        headers = ada | ({"X-Parkour-Client": tool} if tool else {})
        job = client.post("/api/v1/jobs", json=body, headers=headers).json()
        assert (job["submitted_by"], job["submitted_via"]) == ("ada", tool), "the header only labels the tool"


def test_one_person_under_three_tool_names_holds_one_share(client, people, monkeypatch):
    """Issue 40: one token under 3 names got 3.5e9 jumps accepted against a 2e9 share."""
    from backend.services import job_queue

    monkeypatch.setattr(job_queue, "QUEUE_BUDGET_JUMPS", 1000)
    monkeypatch.setattr(job_queue, "PERSON_SHARE", 0.5)  # 500 jumps each: one job of 400, not two
    ada, bob = bearer(people.add("ada")), bearer(people.add("bob"))
    body = {"zeta0s": [0.9], "trials": 4, "cap": 100}  # 400 jumps at its worst
    first = client.post("/api/v1/jobs", json=body, headers=ada | {"X-Parkour-Client": "one"})
    assert first.status_code == 202, first.text
    again = client.post("/api/v1/jobs", json=body, headers=ada | {"X-Parkour-Client": "two"})
    assert again.status_code == 429 and again.json()["detail"].startswith("ada already holds 400 jumps")
    assert client.post("/api/v1/jobs", json=body, headers=bob).status_code == 202, "bob has his own share"


def test_a_read_only_token_reads_and_stops_but_changes_nothing(client, people):
    viewer = bearer(people.add("dash", Access.READ))
    assert client.get("/api/v1/auth", headers=viewer).json() == {"accepted": True, "name": "dash", "access": "read"}
    assert client.get("/api/v1/runs", headers=viewer).status_code == 200
    refused = client.post("/api/v1/runs", json=RUN, headers=viewer)
    assert refused.status_code == 403 and refused.json()["detail"].startswith("dash's token is read-only")
    assert client.get("/api/v1/runs").json()["total"] == 0, "nothing stored"
    stopped = client.post("/api/v1/robot/estop", headers=viewer)  # stopping is always allowed
    assert stopped.status_code == 200
    assert client.get("/api/v1/robot").json()["estop"]["pressed_by"] == "dash"


def test_an_estop_without_a_token_names_the_address(client):
    assert client.post("/api/v1/robot/estop").status_code == 200
    latch = client.get("/api/v1/robot").json()["estop"]
    assert latch["latched"] and latch["pressed_by"] == "someone at testclient"


def test_a_revoked_token_is_refused_at_its_next_request(client, people):
    ada = bearer(people.add("ada"))
    assert client.get("/api/v1/auth", headers=ada).status_code == 200
    people.revoke("ada")  # as parkour token revoke does, while the service runs
    assert client.get("/api/v1/auth", headers=ada).status_code == 401
    assert client.post("/api/v1/runs", json=RUN, headers=ada).status_code == 401
    people.add("ada")  # a new token for the same name: the old one stays refused
    assert client.post("/api/v1/runs", json=RUN, headers=ada).status_code == 401


def test_odd_tokens_are_refused_not_errors(client, people):
    people.add("ada")
    for value in ("Bearer \xfcmlaut-token", "Bearer ", "Basic abc", "Bearer " + "x" * 5000):
        answer = client.get("/api/v1/auth", headers={"Authorization": value.encode("latin-1")})
        assert answer.status_code == 401, value


@pytest.fixture
def exposed(settings, compute):
    """The service as it runs listening beyond its own machine (parkour serve --host 0.0.0.0)."""
    with TestClient(create_app(dataclasses.replace(settings, reads_need_token=True), compute=compute)) as client:
        yield client


def test_off_the_loopback_every_read_needs_a_token(exposed, people, settings):
    reader = bearer(people.add("dash", Access.READ))
    for path in ("/api/v1/runs", "/api/v1/jobs", "/api/v1/robot", "/api/v1/catalog", "/api/v1/experiments"):
        refused = exposed.get(path)
        assert refused.status_code == 401 and "reads need one too" in refused.json()["detail"], path
        assert exposed.get(path, headers=reader).status_code == 200, path
    assert exposed.get("/api/v1/health").status_code == 200, "a health check asks no token"
    assert exposed.get("/panel/").status_code == 200, "the panel's page itself holds no data: it asks for one"
    assert exposed.post("/api/v1/robot/estop").status_code == 200, "stopping needs no token, anywhere"
    assert exposed.post("/api/v1/sim/map", json={}).status_code == 401, "the open simulations are not open here"
    with pytest.raises(WebSocketDisconnect) as closed, exposed.websocket_connect("/api/v1/robot/live"):
        pass
    assert closed.value.code == 1008


def test_the_panels_cookie_opens_reads_and_websockets_never_changes(exposed, people):
    ada = bearer(people.add("ada"))
    signed_in = exposed.get("/api/v1/auth", headers=ada)
    cookie = signed_in.cookies.get("parkour_token")
    assert cookie and "httponly" in signed_in.headers["set-cookie"].lower()
    assert "samesite=strict" in signed_in.headers["set-cookie"].lower()
    assert exposed.get("/api/v1/runs").status_code == 200, "the event streams' way in: the cookie"
    with exposed.websocket_connect("/api/v1/robot/live?rate=10") as live:
        assert "state" in live.receive_json()
    refused = exposed.post("/api/v1/runs", json=RUN)  # the cookie rides along, as a forged form's would
    assert refused.status_code == 401, "a change needs the header: the cookie never authorizes one"
    signed_out = exposed.get("/api/v1/auth")  # no header: nobody, and the cookie goes
    assert signed_out.status_code == 401 and "parkour_token" not in exposed.cookies
    assert exposed.get("/api/v1/runs").status_code == 401
