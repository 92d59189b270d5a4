"""Service exceptions become the right HTTP statuses, and every error is a small JSON answer
(backend/api/errors.py)."""

import dataclasses
import json
import logging

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from tests.backend.api.bodies import RUN

MB = 1_000_000
LEGS = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]


def test_unknown_records_are_404(client, auth):
    assert client.get("/api/v1/runs/999").status_code == 404
    assert client.get("/api/v1/jobs/999").status_code == 404
    assert client.post("/api/v1/runs", json=RUN | {"experiment_id": 999}, headers=auth).status_code == 404


@pytest.mark.parametrize(
    ("method", "path", "status"),
    [
        ("GET", "/nothing-here", 404),
        ("GET", "/api/v1/nothing-here", 404),
        ("GET", "/panel/nothing-here.js", 404),
        ("PUT", "/api/v1/health", 405),
        ("DELETE", "/api/v1/sim/map", 405),
    ],
)
def test_unknown_paths_and_methods_are_json(client, auth, method, path, status):
    response = client.request(method, path, headers=auth)
    assert response.status_code == status
    assert response.headers["content-type"] == "application/json" and response.json()["detail"]


@pytest.fixture
def roomy(settings):
    """The service with a 5 MB body limit, so a 1 MB value reaches validation."""
    roomy = dataclasses.replace(settings, max_request_bytes=5 * MB)
    with TestClient(create_app(roomy, run_jobs=False)) as client:
        yield client


@pytest.mark.parametrize(
    ("path", "body", "loc"),
    [
        ("/api/v1/experiments", {"name": "x" * MB}, ["body", "name"]),
        ("/api/v1/experiments", {"name": "x", "notes": 7, "tags": "t" * MB}, ["body", "notes"]),
        ("/api/v1/runs", RUN | {"controls": [{"psi0_deg": 30, "zeta0": 0.5, "x": "y" * MB}]}, None),
        ("/api/v1/jobs", {"kind": "mjtf", "zeta0s": [2.0] * (MB // 8)}, ["body", "mjtf", "zeta0s"]),
        ("/api/v1/experiments", {"name": "x", "k" * MB: 1}, None),
    ],
)
def test_a_422_quotes_a_few_hundred_bytes_of_a_megabyte_input(roomy, settings, path, body, loc):
    token = (settings.data_dir / "api_token").read_text().strip()
    response = roomy.post(path, json=body, headers={"Authorization": f"Bearer {token}"})
    assert response.status_code == 422 and len(response.content) < 2_000, len(response.content)
    detail = response.json()["detail"]
    assert detail and all({"loc", "msg", "type"} <= error.keys() for error in detail), "FastAPI's shape"
    assert all(len(json.dumps(error.get("input"))) <= 210 for error in detail)
    if loc is not None:
        assert detail[0]["loc"] == loc


def test_a_422_keeps_a_small_input_as_it_was(client, auth):
    response = client.post("/api/v1/runs", json=RUN | {"jumps": 0}, headers=auth)
    assert response.status_code == 422
    (error,) = response.json()["detail"]
    assert error["loc"] == ["body", "jumps"] and error["input"] == 0 and error["type"] == "greater_than_equal"
    assert error["ctx"] == {"ge": 1}


def _bad(value: str, base: dict) -> str:
    """``base`` as JSON text with ``value`` (a JSON literal, or a string's escaped text) at ``where``."""
    return json.dumps(base).replace('"@"', value)


NON_FINITE = ["NaN", "Infinity", "-Infinity", "1e309", "-1e309"]
SURROGATES = ['"\\ud800"', '"ok\\udfff"']
ROBOT_RUN = {"controls": LEGS}
CONNECT = {"url": "loop://"}

FLOAT_FIELDS = [
    ("/api/v1/runs", RUN | {"start": {"xdot": "@", "ydot": -0.17}}, ["body", "start", "xdot"]),
    ("/api/v1/runs", RUN | {"controls": [{"psi0_deg": 30, "zeta0": "@"}]}, ["body", "controls", 0, "zeta0"]),
    ("/api/v1/runs", RUN | {"model": {"mu": "@"}}, ["body", "model", "mu"]),
    ("/api/v1/runs", RUN | {"trajectory_rate": "@"}, ["body", "trajectory_rate"]),
    ("/api/v1/jobs", {"kind": "mjtf", "zeta0s": [0.9, "@"]}, ["body", "mjtf", "zeta0s", 1]),
    (
        "/api/v1/jobs",
        {"kind": "mjtf", "zeta0s": [0.9], "noise": {"velocity": "@"}},
        ["body", "mjtf", "noise", "velocity"],
    ),
    ("/api/v1/jobs", {"kind": "basin", "controls": LEGS, "tolerance": "@"}, ["body", "basin", "tolerance"]),
    ("/api/v1/robot/connect", CONNECT | {"calibration_scale": "@"}, ["body", "calibration_scale"]),
    ("/api/v1/robot/connect", CONNECT | {"calibration_origin": [0.0, "@"]}, ["body", "calibration_origin", 1]),
    ("/api/v1/robot/runs", ROBOT_RUN | {"max_seconds": "@"}, ["body", "max_seconds"]),
    ("/api/v1/robot/runs", ROBOT_RUN | {"closed_loop": {"target_m": "@"}}, ["body", "closed_loop", "target_m"]),
    ("/api/v1/sim/map", {"controls": LEGS, "start": {"xdot": -0.8, "ydot": "@"}}, ["body", "start", "ydot"]),
]
STRING_FIELDS = [
    ("/api/v1/experiments", {"name": "@"}, ["body", "name"]),
    ("/api/v1/experiments", {"name": "x", "description": "@"}, ["body", "description"]),
    ("/api/v1/experiments", {"name": "x", "notes": "@"}, ["body", "notes"]),
    ("/api/v1/experiments", {"name": "x", "tags": ["ok", "@"]}, ["body", "tags", 1]),
    ("/api/v1/runs", RUN | {"tags": ["@"]}, ["body", "tags", 0]),
    ("/api/v1/robot/connect", {"url": "@"}, ["body", "url"]),
    ("/api/v1/robot/connect", CONNECT | {"tracker_host": "@"}, ["body", "tracker_host"]),
    ("/api/v1/robot/connect", CONNECT | {"natnet_version": "@"}, ["body", "natnet_version"]),
    ("/api/v1/robot/connect", CONNECT | {"natnet_multicast_group": "@"}, ["body", "natnet_multicast_group"]),
    ("/api/v1/robot/runs", ROBOT_RUN | {"tags": ["@"]}, ["body", "tags", 0]),
]


@pytest.mark.parametrize("value", NON_FINITE)
@pytest.mark.parametrize(("path", "base", "loc"), FLOAT_FIELDS)
def test_non_finite_numbers_are_422_naming_the_field(client, auth, path, base, loc, value):
    headers = auth | {"Content-Type": "application/json"}
    response = client.post(path, content=_bad(value, base), headers=headers)
    assert response.status_code == 422, response.text
    assert [error["loc"] for error in response.json()["detail"]] == [loc]


@pytest.mark.parametrize("value", SURROGATES)
@pytest.mark.parametrize(("path", "base", "loc"), STRING_FIELDS)
def test_lone_surrogates_are_422_naming_the_field(client, auth, path, base, loc, value):
    headers = auth | {"Content-Type": "application/json"}
    response = client.post(path, content=_bad(value, base), headers=headers)
    assert response.status_code == 422, response.text
    assert [error["loc"] for error in response.json()["detail"]] == [loc]


def test_changes_to_stored_records_refuse_them_too(client, auth):
    run = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    headers = auth | {"Content-Type": "application/json"}
    patched = client.patch(f"/api/v1/runs/{run['id']}", content='{"notes": "a\\ud800"}', headers=headers)
    assert patched.status_code == 422 and patched.json()["detail"][0]["loc"] == ["body", "notes"]
    experiment = client.post("/api/v1/experiments", json={"name": "e"}, headers=auth).json()
    renamed = client.patch(f"/api/v1/experiments/{experiment['id']}", content='{"name": "\\udc00"}', headers=headers)
    assert renamed.status_code == 422 and renamed.json()["detail"][0]["loc"] == ["body", "name"]
    unknown = client.post("/api/v1/experiments", content='{"name": "x", "\\ud800": NaN}', headers=headers)
    # A key pydantic cannot read as text: the body is refused as a whole, the key quoted escaped.
    assert unknown.status_code == 422 and unknown.json()["detail"][0]["input"] == '"\\ud800"'


@pytest.mark.parametrize(
    ("path", "name"),
    [
        ("/api/v1/runs?zeta0_min=nan", "zeta0_min"),
        ("/api/v1/runs?psi0_max=inf", "psi0_max"),
        ("/api/v1/runs/aggregate?zeta0_max=-inf", "zeta0_max"),
        ("/api/v1/jobs/1/events?timeout=nan", "timeout"),
        ("/api/v1/jobs/1/events?timeout=1e309", "timeout"),
    ],
)
def test_non_finite_query_parameters_are_422_naming_them(client, path, name):
    response = client.get(path)
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["query", name]


def test_bodies_that_are_not_json_are_4xx_json(client, auth):
    headers = auth | {"Content-Type": "application/json"}
    for body in (b'{"name": "\xed\xa0\x80"}', b'{"name": ', b"[" * 100_000, b"\xff\xfe"):
        response = client.post("/api/v1/experiments", content=body, headers=headers)
        assert 400 <= response.status_code < 500 and response.json()["detail"], body[:20]


def test_a_server_error_is_json_without_a_traceback_and_is_logged(settings, caplog):
    app = create_app(settings, run_jobs=False)

    @app.get("/api/v1/broken")
    def broken():
        raise RuntimeError("secret internals")

    with TestClient(app, raise_server_exceptions=False) as client, caplog.at_level(logging.ERROR):
        response = client.get("/api/v1/broken")
    assert response.status_code == 500 and response.headers["content-type"] == "application/json"
    assert response.json() == {"detail": "internal server error (logged by the service)"}
    assert "secret" not in response.text and "Traceback" not in response.text
    assert response.headers["x-content-type-options"] == "nosniff"
    logged = [record for record in caplog.records if record.name == "parkourlab.api"]
    assert logged and logged[0].exc_info and "GET /api/v1/broken" in logged[0].getMessage()


@pytest.mark.parametrize(
    ("method", "path", "allow"),
    [
        ("OPTIONS", "/api/v1/runs/1", "DELETE, GET, PATCH"),  # Starlette said GET: the first route's only
        ("PUT", "/api/v1/runs/1", "DELETE, GET, PATCH"),
        ("DELETE", "/api/v1/runs", "GET, POST"),
        ("PATCH", "/api/v1/runs/aggregate", "GET"),  # was a 422 about run_id: the path names no run
        ("DELETE", "/api/v1/runs/export", "GET"),
        ("PUT", "/api/v1/jobs/1", "GET"),
    ],
)
def test_a_method_a_path_does_not_take_is_a_405_listing_every_method_it_does(client, auth, method, path, allow):
    response = client.request(method, path, headers=auth)
    assert response.status_code == 405 and response.headers["allow"] == allow
    assert response.json()["detail"] == f"method {method} not allowed on {path}; it takes {allow}"


def test_a_run_id_that_is_no_number_is_still_a_422_naming_it(client):
    response = client.get("/api/v1/runs/abc")
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["path", "run_id"]
