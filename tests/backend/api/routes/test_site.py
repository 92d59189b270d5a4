"""The service itself: health, the panel, offline docs, static assets compressed (backend/api/routes/site.py)."""

import gzip

import pytest

from backend.api.routes.site import PLOTLY_JS, takes_gzip


def test_health_index_and_offline_docs(client):
    assert client.get("/api/v1/health").json()["status"] == "ok"
    page = client.get("/")
    assert page.status_code == 200 and "/docs" in page.text
    docs = client.get("/docs").text
    assert "cdn" not in docs.lower() and "/static/swagger/swagger-ui-bundle.js" in docs, "no CDN at run time"
    assert client.get("/static/swagger/swagger-ui-bundle.js").status_code == 200
    assert client.get("/openapi.json").json()["info"]["title"] == "ParkourLab"


def test_auth_says_whether_the_token_is_accepted(client, auth):
    """What the panel shows beside its token field: 200 and whose it is, 401 for nobody's."""
    assert client.get("/api/v1/auth", headers=auth).json() == {"accepted": True, "name": "lab", "access": "write"}
    assert client.get("/api/v1/auth").status_code == 401
    assert client.get("/api/v1/auth", headers={"Authorization": "Bearer not-the-token"}).status_code == 401


def _sent(client, path: str, encoding: str, **headers) -> tuple[int, bytes, dict]:
    """(bytes on the wire, the body as the browser reads it, the headers) of GET ``path``."""
    with client.stream("GET", path, headers={"Accept-Encoding": encoding, **headers}) as response:
        assert response.status_code == 200, path
        wire = b"".join(response.iter_raw())
        headers = dict(response.headers)
    body = gzip.decompress(wire) if headers.get("content-encoding") == "gzip" else wire
    return len(wire), body, headers


def test_static_assets_go_compressed_to_a_browser_that_takes_gzip(client):
    """Plotly went as 4.8 MB on every panel load: compressed it is under a third of that, the
    same file once decompressed; so are the panel's modules and the docs' bundle. A client that
    takes no gzip gets the files as they are, and every answer says it varies by Accept-Encoding."""
    plotly = PLOTLY_JS.read_bytes()
    plain_bytes, plain, plain_headers = _sent(client, "/static/plotly.min.js", "identity")
    gz_bytes, unpacked, headers = _sent(client, "/static/plotly.min.js", "gzip, deflate, br")
    print(f"plotly.min.js: {plain_bytes:,} B as it is, {gz_bytes:,} B compressed")  # measured
    assert plain_bytes == len(plotly) and plain == plotly and "content-encoding" not in plain_headers
    assert headers["content-encoding"] == "gzip" and unpacked == plotly
    assert gz_bytes < len(plotly) / 3
    assert headers["vary"] == plain_headers["vary"] == "Accept-Encoding"
    assert headers["content-type"].startswith("text/javascript")
    assert "script-src 'self'" in headers["content-security-policy"], "the security headers are kept"
    again = client.get("/static/plotly.min.js", headers={"Accept-Encoding": "gzip", "If-None-Match": headers["etag"]})
    assert again.status_code == 304 and not again.content, "a browser that has it is told so, with no body"
    smaller = (("/panel/jobs.js", 2.0), ("/panel/index.html", 2.0), ("/static/swagger/swagger-ui-bundle.js", 2.5))
    for path, at_least in smaller:
        plain_bytes, plain, _ = _sent(client, path, "identity")
        gz_bytes, unpacked, headers = _sent(client, path, "gzip")
        assert headers.get("content-encoding") == "gzip" and unpacked == plain, path
        assert gz_bytes * at_least < plain_bytes, (path, plain_bytes, gz_bytes)


def test_api_answers_are_not_compressed(client):
    """Only static assets are compressed: an API answer goes as it is (its event streams too,
    tests/backend/api/test_robot_events.py), whatever the client takes."""
    response = client.get("/api/v1/runs?limit=5", headers={"Accept-Encoding": "gzip"})
    assert response.status_code == 200 and "content-encoding" not in response.headers


@pytest.mark.parametrize(
    ("header", "takes"),
    [("gzip", True), ("gzip, deflate, br", True), ("br;q=1.0, GZIP;q=0.5", True), ("*", True), ("gzip;q=0", False),
     ("identity", False), (None, False), ("deflate, br", False), ("gzip;q=x", False)],
)  # fmt: skip
def test_which_clients_take_gzip(header, takes):
    assert takes_gzip(header) is takes


class _Warming:
    """The service's pools as just after a start: the reads and the job worker still loading."""

    def ready(self) -> bool:
        return False

    def warming(self) -> list[str]:
        return ["reads", "jobs"]


def test_health_says_warming_and_what_until_the_request_pools_are_warm(client):
    state = client.app.state
    pools, state.compute = state.compute, _Warming()
    try:
        health = client.get("/api/v1/health")
    finally:
        state.compute = pools
    assert health.status_code == 200, "up and answering: a start-up probe passes"
    assert (health.json()["status"], health.json()["warming"]) == ("warming", ["reads", "jobs"])
    never_warmed = client.get("/api/v1/health").json()  # the tests' pools: nothing to wait for
    assert never_warmed["status"] == "ok" and never_warmed["warming"] == []
