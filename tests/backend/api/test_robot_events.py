"""GET /api/v1/robot/events, the panel's server-sent events, under a real uvicorn (TestClient reads
a response whole, and this one never ends on its own): the latch at once, a press soon after, the
stream gone with its client or its service, and a bound on how many are open."""

import json
import signal
import socket
import threading
import time

import httpx
import pytest
import uvicorn

from backend.api import robot_events
from backend.api.app import create_app
from tests.helpers import start_service

READ_GUARD_S = 5.0  # [s] a read that waits longer fails the test instead of hanging it (not a latency claim)
STOP_GUARD_S = 20.0  # [s] likewise for a service asked to stop


def _latch(event: dict) -> tuple:
    """The latch as the panel reads it (the status may say more of it: acknowledged, since)."""
    return event["estop"]["latched"], event["estop"]["reason"]


@pytest.fixture
def database_url():
    """SQLite only: the stream reads the robot service, not the store."""
    return None


@pytest.fixture
def served(settings, compute):
    """``(base URL, app, auth headers)``: the app under a real uvicorn, in a thread, on a socket bound
    here to a port of its own (a port picked free and bound later may be taken in between)."""
    listening = socket.create_server(("127.0.0.1", 0))
    port = listening.getsockname()[1]
    app = create_app(settings, run_jobs=False, compute=compute)
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [listening]}, name="uvicorn", daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not server.started:
        assert time.monotonic() < deadline and thread.is_alive(), "uvicorn did not start"
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}", app, {"Authorization": f"Bearer {app.state.token}"}
    server.should_exit = True
    thread.join(10)
    listening.close()
    assert not thread.is_alive(), "uvicorn stopped (no stream was left open)"


class Events:
    """An open event stream, read one event at a time: :meth:`next` is the next ``event: robot``'s
    data (comments and the ``retry`` line are kept in :attr:`other`)."""

    def __init__(self, client: httpx.Client, url: str):
        self.response = client.send(client.build_request("GET", url), stream=True)
        self.lines = self.response.iter_lines()
        self.other: list[str] = []

    def next(self) -> dict:
        event, data = None, []
        for line in self.lines:
            if line == "":
                if event == "robot":
                    return json.loads("\n".join(data))
                event, data = None, []
            elif line.startswith("event: "):
                event = line.removeprefix("event: ")
            elif line.startswith("data: "):
                data.append(line.removeprefix("data: "))
            else:
                self.other.append(line)
        raise AssertionError("the stream ended")

    def close(self) -> None:
        self.response.close()


def _client() -> httpx.Client:
    return httpx.Client(timeout=httpx.Timeout(READ_GUARD_S))


def _until(predicate, what: str, timeout: float = READ_GUARD_S) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"not within {timeout:g} s: {what}"
        time.sleep(0.02)


def test_the_first_event_is_the_robot_now_and_the_stream_is_held_to_the_security_rules(served):
    base, _app, _auth = served
    with _client() as client:
        events = Events(client, f"{base}/api/v1/robot/events")  # no token: reading needs none
        try:
            headers = events.response.headers
            assert events.response.status_code == 200
            assert headers["content-type"].startswith("text/event-stream")
            assert "content-encoding" not in headers, "not compressed (httpx takes gzip): nothing held back"
            assert headers["cache-control"] == "no-cache" and headers["x-content-type-options"] == "nosniff"
            assert "script-src 'self'" in headers["content-security-policy"]
            first = events.next()
            assert set(first) == {"estop", "state", "run"}
            assert (_latch(first), first["state"], first["run"]) == ((False, None), "disconnected", None)
            assert events.other[0] == f"retry: {robot_events.RECONNECT_MS}", "the browser reconnects soon"
        finally:
            events.close()
        refused = client.get(f"{base}/api/v1/robot/events", headers={"Host": "evil.example"})
        assert refused.status_code == 400 and "host not allowed" in refused.json()["detail"]


def test_a_press_latches_in_the_stream_and_a_reset_releases_it(served, virtual, patient_estop):
    base, _app, auth = served
    robot, tracker_port = virtual
    with _client() as client:
        body = {"url": robot.url, "tracker_port": tracker_port}
        assert client.post(f"{base}/api/v1/robot/connect", json=body, headers=auth).status_code == 200
        try:
            events = Events(client, f"{base}/api/v1/robot/events")
            try:
                first = events.next()
                assert (first["state"], _latch(first)) == ("disarmed", (False, None))
                pressed = time.monotonic()
                stopped = client.post(f"{base}/api/v1/robot/estop").json()  # no token: stopping is always allowed
                assert stopped["acknowledged"] is True, stopped
                latched = events.next()
                print(f"press to event: {1000 * (time.monotonic() - pressed):.0f} ms")
                latch, reason = _latch(latched)
                assert latch is True and "stop" in reason, latched["estop"]
                assert client.post(f"{base}/api/v1/robot/reset", headers=auth).status_code == 200
                while (released := events.next())["estop"]["latched"]:
                    pass  # the reset may pass through states on its way
                assert _latch(released) == (False, None) and released["state"] == "disarmed"
            finally:
                events.close()
        finally:
            client.post(f"{base}/api/v1/robot/disconnect", headers=auth)


def test_the_stream_ends_when_its_client_goes_away(served):
    base, app, _auth = served
    with _client() as client:
        events = Events(client, f"{base}/api/v1/robot/events")
        events.next()
        assert app.state.robot_event_streams.open == 1
        events.close()
    _until(lambda: app.state.robot_event_streams.open == 0, "the stream's end gave its place back")


def test_a_quiet_stream_sends_keep_alive_comments(served, monkeypatch):
    base, _app, _auth = served
    monkeypatch.setattr(robot_events, "KEEP_ALIVE_S", 0.3)  # 10 s in service
    with _client() as client:
        events = Events(client, f"{base}/api/v1/robot/events")
        try:
            events.next()
            _until(lambda: next(events.lines) == ": keep-alive", "a comment line while nothing changes")
        finally:
            events.close()


def test_streams_past_the_bound_are_refused_until_one_closes(served, monkeypatch):
    base, app, _auth = served
    monkeypatch.setattr(robot_events, "MAX_EVENT_STREAMS", 2)
    with _client() as client:
        held = [Events(client, f"{base}/api/v1/robot/events") for _ in range(2)]
        try:
            for events in held:
                events.next()
            refused = client.get(f"{base}/api/v1/robot/events")
            assert refused.status_code == 503
            assert refused.json()["detail"] == robot_events.TOO_MANY_STREAMS.format(2)
            held.pop().close()
            _until(lambda: app.state.robot_event_streams.open == 1, "a closed stream gave its place back")
            again = Events(client, f"{base}/api/v1/robot/events")
            held.append(again)
            assert again.response.status_code == 200 and again.next()["state"] == "disconnected"
        finally:
            for events in held:
                events.close()


@pytest.mark.slow
def test_a_service_with_an_open_stream_stops_on_sigterm(tmp_path):
    """uvicorn waits for every response to end before it stops: the stream sees the signal and
    ends, so `parkour serve` stops as it would without it (it used to wait forever)."""
    process = start_service(tmp_path / "data", 0, "--no-view")
    try:
        with _client() as client:
            events = Events(client, f"http://127.0.0.1:{process.port}/api/v1/robot/events")
            assert events.next()["state"] == "disconnected"
            asked = time.monotonic()
            process.send_signal(signal.SIGTERM)
            with pytest.raises(AssertionError, match="the stream ended"):
                events.next()  # the stream ends, cleanly, with the service
            assert process.wait(STOP_GUARD_S) in (0, -signal.SIGTERM), "stopped (uvicorn re-raises the signal)"
            print(f"SIGTERM to exit: {1000 * (time.monotonic() - asked):.0f} ms")
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
