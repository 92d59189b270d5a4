"""The token and the request limits (backend/api/security.py)."""

from tests.backend.api.bodies import RUN


def test_changes_need_the_token(client, auth):
    assert client.post("/api/v1/experiments", json={"name": "x"}).status_code == 401
    wrong = {"Authorization": "Bearer not-the-token"}
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=wrong).status_code == 401
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=auth).status_code == 201
    assert client.get("/api/v1/experiments").status_code == 200, "reads are open"


def test_oversized_requests_are_refused(client, auth):
    huge = RUN | {"tags": ["x" * 60] * 20_000}
    assert client.post("/api/v1/runs", json=huge, headers=auth).status_code == 413
