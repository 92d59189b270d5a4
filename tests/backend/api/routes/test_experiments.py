"""Experiments through the API (backend/api/routes/experiments.py)."""

from tests.backend.api.bodies import RUN


def test_experiment_lifecycle(client, auth):
    created = client.post(
        "/api/v1/experiments", json={"name": "retraction", "tags": ["fig8"], "description": "d"}, headers=auth
    ).json()
    experiment = created["id"]
    patched = client.patch(f"/api/v1/experiments/{experiment}", json={"notes": "looks good"}, headers=auth).json()
    assert patched["notes"] == "looks good" and patched["name"] == "retraction"
    run = client.post("/api/v1/runs", json=RUN | {"experiment_id": experiment}, headers=auth).json()
    assert client.get(f"/api/v1/experiments/{experiment}").json()["runs"] == 1
    assert client.delete(f"/api/v1/experiments/{experiment}", headers=auth).status_code == 409, "runs first"
    assert client.delete(f"/api/v1/runs/{run['id']}", headers=auth).status_code == 204
    assert client.delete(f"/api/v1/experiments/{experiment}", headers=auth).status_code == 204
    assert client.get(f"/api/v1/experiments/{experiment}").status_code == 404
