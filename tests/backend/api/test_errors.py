"""Service exceptions become the right HTTP statuses (backend/api/errors.py)."""

from tests.backend.api.bodies import RUN


def test_unknown_records_are_404(client, auth):
    assert client.get("/api/v1/runs/999").status_code == 404
    assert client.get("/api/v1/jobs/999").status_code == 404
    assert client.post("/api/v1/runs", json=RUN | {"experiment_id": 999}, headers=auth).status_code == 404
