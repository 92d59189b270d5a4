"""Experiments through the API (backend/api/routes/experiments.py)."""

import pytest

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


def test_an_experiments_page_has_its_outcomes_endings_and_jobs(client, auth):
    """GET /experiments/{id}/summary: its notes, the climb and jumps of its runs (mean, std and the
    mean's 95% interval, over all and by kind), how its runs ended, its jobs newest first."""
    experiment = client.post("/api/v1/experiments", json={"name": "seeds", "notes": "three seeds"}, headers=auth).json()
    empty = client.get(f"/api/v1/experiments/{experiment['id']}/summary").json()
    assert (empty["runs"], empty["outcomes"], empty["by_kind"], empty["jobs"]) == (0, None, [], [])
    climbs = []
    for ydot in (-0.2, -0.18, -0.16):
        body = RUN | {"experiment_id": experiment["id"], "start": {"xdot": -0.93, "ydot": ydot}}
        climbs.append(client.post("/api/v1/runs", json=body, headers=auth).json()["climb"])
    client.post("/api/v1/runs", json=RUN, headers=auth)  # not in it
    job = {"experiment_id": experiment["id"], "psi0_deg": 30, "zeta0s": [0.9], "trials": 1, "cap": 5}
    jobs = [client.post("/api/v1/jobs", json=job, headers=auth).json()["id"] for _ in range(2)]
    summary = client.get(f"/api/v1/experiments/{experiment['id']}/summary").json()
    assert summary["experiment"]["notes"] == "three seeds" and summary["runs"] == 3
    climb = summary["outcomes"]["climb"]
    mean = sum(climbs) / 3
    sample_std = (sum((c - mean) ** 2 for c in climbs) / 2) ** 0.5
    assert climb["mean"] == pytest.approx(mean)
    assert climb["ci95_high"] - climb["mean"] == pytest.approx(4.3027 * sample_std / 3**0.5, rel=1e-6)
    assert [(group["key"], group["runs"]) for group in summary["by_kind"]] == [("sim", 3)]
    assert summary["statuses"] == {"done": 3} and summary["end_reasons"] == {} and summary["loops"] == {"open": 3}
    assert [job["id"] for job in summary["jobs"]] == jobs[::-1] and summary["jobs_total"] == 2
    assert client.get("/api/v1/experiments/999/summary").status_code == 404
    page = client.get("/api/v1/experiments").json()
    assert page["total"] == 1 and page["items"][0]["runs"] == 3
    assert client.get("/api/v1/jobs", params={"experiment_id": experiment["id"], "limit": 1}).json()["total"] == 2
