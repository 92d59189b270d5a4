"""The token, the request limits, the Host and Origin allow-list and the security headers
(backend/api/security.py)."""

import re
import select
import socket
import threading
import time
from pathlib import Path

import pytest
import uvicorn
from fastapi.routing import APIRoute, iter_route_contexts
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from backend.api.app import create_app
from backend.api.security import require_token
from backend.settings import Settings
from tests.backend.api.asgi import CHUNK, send_chunked
from tests.backend.api.bodies import RUN
from tests.helpers import free_port

MiB = 2**20
PANEL = Path(__file__).resolve().parents[3] / "frontend" / "panel"


def test_changes_need_the_token(client, auth):
    assert client.post("/api/v1/experiments", json={"name": "x"}).status_code == 401
    wrong = {"Authorization": "Bearer not-the-token"}
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=wrong).status_code == 401
    odd = {"Authorization": "Bearer tök".encode("latin-1")}  # not ASCII: refused, not a 500
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=odd).status_code == 401
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=auth).status_code == 201
    assert client.get("/api/v1/experiments").status_code == 200, "reads are open"


def test_oversized_requests_are_refused(client, auth):
    huge = RUN | {"tags": ["x" * 60] * 20_000}
    response = client.post("/api/v1/runs", json=huge, headers=auth)
    assert response.status_code == 413 and "at most" in response.json()["detail"]


# Streamed bodies ------------------------------------------------------------------------------
def test_a_chunked_body_over_the_limit_is_refused_without_reading_the_rest(client, auth, settings):
    answer = send_chunked(client.app, "POST", "/api/v1/experiments", total=5 * MiB, headers=auth)
    assert answer.status == 413 and "at most" in answer.json()["detail"]
    assert answer.headers["content-type"] == "application/json" and answer.headers["connection"] == "close"
    # It stopped at the first chunk past the limit: the other ~4 MB were never pulled.
    assert settings.max_request_bytes < answer.pulled <= settings.max_request_bytes + CHUNK


def test_a_chunked_body_within_the_limit_is_served(client, auth):
    body = (b'{"name": "streamed", "notes": "%s"}' % (b"n" * 50_000),)
    response = client.post(
        "/api/v1/experiments", content=iter(body), headers=auth | {"Content-Type": "application/json"}
    )
    assert response.request.headers["transfer-encoding"] == "chunked"
    assert response.status_code == 201 and response.json()["name"] == "streamed"


@pytest.mark.parametrize("token", [None, "Bearer not-the-token"])
def test_the_token_is_checked_before_the_body_is_read(client, token):
    headers = {} if token is None else {"Authorization": token}
    answer = send_chunked(client.app, "POST", "/api/v1/runs", total=5 * MiB, headers=headers)
    assert answer.status == 401 and answer.headers["www-authenticate"] == "Bearer"
    assert "token" in answer.json()["detail"]
    assert answer.pulled == 0, "refused before a byte of the body was read"


def test_the_estop_needs_no_token_but_its_body_is_bounded(client):
    assert client.post("/api/v1/robot/estop").status_code == 200, "stopping is always allowed"
    answer = send_chunked(client.app, "POST", "/api/v1/robot/estop", total=5 * MiB)
    assert answer.status == 413 and answer.pulled <= client.app.state.settings.max_request_bytes + CHUNK


def test_the_only_changes_open_without_the_token_are_the_estop_and_the_simulations(client):
    """The middleware asks the token of exactly the routes that declare ``require_token``; these
    are the mutating routes that do not (a new one must be a decision, made here)."""
    open_routes = {
        (method, route.path)
        for route in iter_route_contexts(client.app.routes)  # FastAPI includes routers lazily
        if isinstance(route.original_route, APIRoute)
        for method in route.methods & {"POST", "PUT", "PATCH", "DELETE"}
        if not any(dependency.call is require_token for dependency in route.dependant.dependencies)
    }
    assert open_routes == {
        ("POST", "/api/v1/robot/estop"),
        ("POST", "/api/v1/sim/map"),
        ("POST", "/api/v1/sim/trajectory"),
        ("POST", "/api/v1/sim/fixed-point"),
    }
    for _method, path in open_routes - {("POST", "/api/v1/robot/estop")}:
        assert client.post(path, json={}).status_code == 422, "validated, not refused for the token"
    # An unknown change is a 401 before it is a 404: nothing is said to a caller without the token.
    assert client.post("/api/v1/nothing-here").status_code == 401


@pytest.fixture
def server(settings):
    """The app under a real uvicorn on a free port, in a thread."""
    port = free_port()
    app = create_app(settings, run_jobs=False)
    uvicorn_server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=uvicorn_server.run, name="uvicorn", daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not uvicorn_server.started:
        assert time.monotonic() < deadline and thread.is_alive(), "uvicorn did not start"
        time.sleep(0.05)
    yield port, app.state.token
    uvicorn_server.should_exit = True
    thread.join(10)


def test_a_real_server_answers_413_to_a_300_mib_chunked_body_after_the_limit(server, settings):
    port, token = server
    head = (
        "POST /api/v1/experiments HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
        f"Authorization: Bearer {token}\r\nTransfer-Encoding: chunked\r\n\r\n"
    ).encode()
    chunk = b"x" * CHUNK
    framed = b"%x\r\n%s\r\n" % (len(chunk), chunk)
    sent, answered = 0, b""
    with socket.create_connection(("127.0.0.1", port), timeout=5) as connection:
        connection.sendall(head)
        try:
            while sent < 300 * MiB and not select.select([connection], [], [], 0)[0]:
                connection.sendall(framed)  # blocks (then times out) once the server stops reading
                sent += len(chunk)
        except (BrokenPipeError, ConnectionResetError, TimeoutError):
            pass
        try:
            while part := connection.recv(65536):
                answered += part
        except (ConnectionResetError, TimeoutError):
            pass
    print(f"sent {sent / MiB:.1f} MiB before the 413")
    assert answered.startswith(b"HTTP/1.1 413"), answered[:200]
    assert b'"detail"' in answered and b"connection: close" in answered.lower()
    # What was sent before the answer: the limit, and what the sockets' buffers held.
    assert sent < settings.max_request_bytes + 16 * MiB, f"{sent / MiB:.0f} MiB sent before the 413"


# Host and Origin ------------------------------------------------------------------------------
@pytest.mark.parametrize("host", ["localhost:8000", "127.0.0.1", "127.0.0.1:8000", "[::1]:8000", "LOCALHOST"])
def test_loopback_hosts_are_allowed(client, host):
    assert client.get("/api/v1/health", headers={"Host": host}).status_code == 200


@pytest.mark.parametrize(
    "host", ["evil.example", "evil.example:8000", "localhost.evil.example", "127.0.0.2", "", "a b"]
)
def test_a_foreign_host_is_refused(client, auth, host):
    for method, path, headers in (("GET", "/api/v1/health", {}), ("POST", "/api/v1/experiments", auth)):
        response = client.request(method, path, headers={"Host": host} | headers, json={"name": "x"})
        assert response.status_code == 400, (method, host)
        assert "host" in response.json()["detail"]
        assert response.headers["x-content-type-options"] == "nosniff"
    assert client.get("/api/v1/experiments").json()["items"] == [], "nothing was created"


def test_named_hosts_are_allowed_from_the_settings_and_the_environment(tmp_path, monkeypatch):
    monkeypatch.setenv("PARKOUR_ALLOWED_HOSTS", "lab-pc.example, 10.0.0.5 [fe80::1]")
    settings = Settings.from_environment(tmp_path / "data", allowed_hosts=["bench", "0.0.0.0"])
    assert set(settings.allowed_hosts) >= {"localhost", "127.0.0.1", "::1", "lab-pc.example", "10.0.0.5", "fe80::1"}
    assert "bench" in settings.allowed_hosts and "0.0.0.0" not in settings.allowed_hosts, "a wildcard is no name"
    with TestClient(create_app(settings, run_jobs=False)) as client:
        for host in ("lab-pc.example:8000", "10.0.0.5", "[fe80::1]:8000", "bench"):
            assert client.get("/api/v1/health", headers={"Host": host}).status_code == 200, host
        assert client.get("/api/v1/health", headers={"Host": "testserver"}).status_code == 400


def test_websockets_from_a_foreign_origin_are_refused(client):
    for origin in ("http://evil.example", "http://localhost.evil.example:8000", "null", "file://", "ftp://localhost"):
        with (
            pytest.raises(WebSocketDisconnect) as refused,
            client.websocket_connect("/api/v1/robot/live", headers={"Origin": origin}) as live,
        ):
            live.receive_json()
        assert refused.value.code == 1008, origin
    with (
        pytest.raises(WebSocketDisconnect),
        client.websocket_connect("/api/v1/robot/live", headers={"Host": "evil.example"}) as live,
    ):
        live.receive_json()


@pytest.mark.parametrize("origin", [None, "http://localhost:8000", "http://127.0.0.1:8001", "https://[::1]"])
def test_websockets_from_an_allowed_origin_or_none_are_served(client, origin):
    headers = {} if origin is None else {"Origin": origin}
    with client.websocket_connect("/api/v1/robot/live?rate=50", headers=headers) as live:
        assert live.receive_json()["state"] == "disconnected"


# Security headers -----------------------------------------------------------------------------
def _csp(response) -> dict[str, str]:
    policy = response.headers["content-security-policy"]
    return {part.split()[0]: part.strip() for part in policy.split(";") if part.strip()}


@pytest.mark.parametrize(
    ("method", "path", "status"),
    [
        ("GET", "/panel/", 200),
        ("GET", "/api/v1/health", 200),
        ("GET", "/docs", 200),
        ("GET", "/static/swagger-init.js", 200),
        ("GET", "/nothing-here", 404),
        ("POST", "/api/v1/experiments", 401),
    ],
)
def test_every_response_carries_the_security_headers(client, method, path, status):
    response = client.request(method, path, headers={"Host": "localhost:8000"})
    assert response.status_code == status
    assert response.headers["x-content-type-options"] == "nosniff"
    assert response.headers["referrer-policy"] == "no-referrer"
    csp = _csp(response)
    assert csp["script-src"] == "script-src 'self'", "no inline or eval'd script"
    assert csp["frame-ancestors"] == "frame-ancestors 'self'", "only the panel's own origin embeds it"
    assert csp["object-src"] == "object-src 'none'"
    assert "ws://localhost:8000" in csp["connect-src"], "the live websocket"
    assert "http://localhost:*" in csp["frame-src"], "the 3D view, on its own port of the same host"
    assert "data:" in csp["img-src"] and "blob:" in csp["img-src"]


def test_the_docs_run_no_inline_script(client):
    page = client.get("/docs")
    assert page.status_code == 200 and 'id="swagger-ui"' in page.text
    scripts = re.findall(r"<script\b([^>]*)>(.*?)</script>", page.text, flags=re.S)
    assert scripts and all("src=" in attributes and not body.strip() for attributes, body in scripts), scripts
    init = client.get("/static/swagger-init.js")
    assert init.headers["content-type"].startswith("text/javascript") and "SwaggerUIBundle(" in init.text
    assert '"/openapi.json"' in init.text and client.get("/openapi.json").status_code == 200


def test_the_panel_runs_no_inline_script():
    """The panel's page under the CSP: scripts from files only, no inline handlers or javascript: URLs."""
    html = (PANEL / "index.html").read_text()
    scripts = re.findall(r"<script\b([^>]*)>(.*?)</script>", html, flags=re.S)
    assert scripts and all("src=" in attributes and not body.strip() for attributes, body in scripts)
    assert not re.search(r"\son[a-z]+\s*=", html) and "javascript:" not in html
