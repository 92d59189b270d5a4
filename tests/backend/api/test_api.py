"""The REST API against the real app and a real SQLite file (httpx through TestClient)."""

import csv
import io
import json
import math
import time

import numpy as np
import pytest

from sim_core import get_preset
from sim_core.mjtf import mjtf_study
from sim_core.noise import NoiseModel

RUN = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.93, "ydot": -0.17}, "jumps": 4}


def test_health_index_and_offline_docs(client):
    assert client.get("/api/v1/health").json()["status"] == "ok"
    page = client.get("/")
    assert page.status_code == 200 and "/docs" in page.text
    docs = client.get("/docs").text
    assert "cdn" not in docs.lower() and "/static/swagger/swagger-ui-bundle.js" in docs, "no CDN at run time"
    assert client.get("/static/swagger/swagger-ui-bundle.js").status_code == 200
    assert client.get("/openapi.json").json()["info"]["title"] == "ParkourLab"


def test_changes_need_the_token(client, auth):
    assert client.post("/api/v1/experiments", json={"name": "x"}).status_code == 401
    wrong = {"Authorization": "Bearer not-the-token"}
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=wrong).status_code == 401
    assert client.post("/api/v1/experiments", json={"name": "x"}, headers=auth).status_code == 201
    assert client.get("/api/v1/experiments").status_code == 200, "reads are open"


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


def test_run_matches_the_simulator_and_stores_its_path(client, auth):
    body = RUN | {"trajectory_rate": 40.0, "tags": ["a", "b"]}
    run = client.post("/api/v1/runs", json=body, headers=auth).json()
    direct = client.post("/api/v1/sim/map", json={k: RUN[k] for k in ("controls", "start", "jumps")}).json()
    assert run["results"]["states"] == direct["states"] and run["jumps_completed"] == 4
    assert run["climb"] == pytest.approx(sum(direct["rises"])) and run["tags"] == ["a", "b"]
    path = client.get(f"/api/v1/runs/{run['id']}/trajectory").json()["columns"]
    assert len(path["time"]) == len(path["y"]) > 100
    assert (
        run["created_at"].endswith("Z")
        and client.get(f"/api/v1/runs/{run['id']}").json()["created_at"] == run["created_at"]
    )


def test_run_lists_filter_and_page(client, auth):
    for zeta0, tag in [(0.86, "low"), (0.88, "low"), (0.9, "mid"), (0.92, "high"), (0.94, "high")]:
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}], "tags": [tag]}
        assert client.post("/api/v1/runs", json=body, headers=auth).status_code == 201
    in_range = client.get("/api/v1/runs", params={"zeta0_min": 0.87, "zeta0_max": 0.93}).json()["items"]
    assert sorted(run["controls"][0][1] for run in in_range) == [0.88, 0.9, 0.92]
    assert [run["tags"] for run in client.get("/api/v1/runs", params={"tag": "high"}).json()["items"]] == [["high"]] * 2
    seen, cursor = [], None
    while True:
        page = client.get("/api/v1/runs", params={"limit": 2} | ({"cursor": cursor} if cursor else {})).json()
        seen += [run["id"] for run in page["items"]]
        if (cursor := page["next_cursor"]) is None:
            break
    assert seen == sorted(seen, reverse=True) and len(seen) == len(set(seen)) == 5


def _seed_runs(client, auth):
    ids = []
    for zeta0, tag in [(0.88, "low"), (0.88, "low"), (0.92, "high")]:
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}], "tags": [tag, "all"]}
        ids.append(client.post("/api/v1/runs", json=body, headers=auth).json()["id"])
    return ids


def test_export_csv_and_json(client, auth):
    ids = _seed_runs(client, auth)
    exported = client.get("/api/v1/runs/export", params={"format": "csv", "tag": "low"})
    assert exported.status_code == 200 and exported.headers["content-type"].startswith("text/csv")
    rows = list(csv.DictReader(io.StringIO(exported.text)))
    assert [int(row["id"]) for row in rows] == ids[:2]
    assert {"tags", "duration_s", "created_at", "climb", "leg0.zeta0", "model.alpha"} <= set(rows[0])
    assert rows[0]["tags"] == "all low"
    as_json = client.get("/api/v1/runs/export", params={"format": "json"}).json()
    assert [row["id"] for row in as_json] == ids and as_json[2]["leg0.zeta0"] == 0.92
    assert client.get("/api/v1/runs/export", params={"format": "xml"}).status_code == 422


def test_compare_shows_only_what_differs(client, auth):
    first, second, third = _seed_runs(client, auth)
    same = client.get("/api/v1/runs/compare", params={"ids": [first, second]}).json()
    assert set(same["differing"]) <= {"id", "created_at", "duration_s"}
    differ = client.get("/api/v1/runs/compare", params={"ids": [first, third]}).json()
    assert {"leg0.zeta0", "climb", "tags"} <= set(differ["differing"]) and "model.alpha" not in differ["fields"]
    assert [run["leg0.zeta0"] for run in differ["runs"]] == [0.88, 0.92]
    assert client.get("/api/v1/runs/compare", params={"ids": [first]}).status_code == 422
    assert client.get("/api/v1/runs/compare", params={"ids": [first, 999]}).status_code == 404


def test_aggregate_groups_runs(client, auth):
    _seed_runs(client, auth)
    by_zeta0 = client.get("/api/v1/runs/aggregate", params={"by": "zeta0"}).json()["groups"]
    assert [(group["key"], group["runs"]) for group in by_zeta0] == [(0.88, 2), (0.92, 1)]
    low = by_zeta0[0]["climb"]
    assert low["std"] == pytest.approx(0.0, abs=1e-9) and low["min"] == low["max"] == pytest.approx(low["mean"])
    by_tag = client.get("/api/v1/runs/aggregate", params={"by": "tag"}).json()["groups"]
    assert [(group["key"], group["runs"]) for group in by_tag] == [("all", 3), ("high", 1), ("low", 2)]
    assert client.get("/api/v1/runs/aggregate", params={"by": "secret"}).status_code == 422


@pytest.mark.parametrize(
    ("body", "field"),
    [
        (RUN | {"controls": [{"psi0_deg": 30, "zeta0": 1.2}]}, "zeta0"),
        (RUN | {"controls": [{"psi0_deg": 95, "zeta0": 0.9}]}, "psi0_deg"),
        (RUN | {"start": {"xdot": 0.5, "ydot": 0}}, "xdot"),
        (RUN | {"jumps": 10**7}, "jumps"),
        (RUN | {"model": {"alpha": -1}}, "alpha"),
        (RUN | {"unknown": 1}, "unknown"),
    ],
)
def test_bad_input_is_a_422_naming_the_field(client, auth, body, field):
    response = client.post("/api/v1/runs", json=body, headers=auth)
    assert response.status_code == 422
    assert any(field in error["loc"] for error in response.json()["detail"]), response.json()


def test_oversized_requests_are_refused(client, auth):
    huge = RUN | {"tags": ["x" * 60] * 20_000}
    assert client.post("/api/v1/runs", json=huge, headers=auth).status_code == 413


def test_unknown_records_are_404(client, auth):
    assert client.get("/api/v1/runs/999").status_code == 404
    assert client.get("/api/v1/jobs/999").status_code == 404
    assert client.post("/api/v1/runs", json=RUN | {"experiment_id": 999}, headers=auth).status_code == 404


def _wait(client, job_id, states=("done", "failed", "cancelled"), timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        job = client.get(f"/api/v1/jobs/{job_id}").json()
        if job["state"] in states:
            return job
        time.sleep(0.05)
    pytest.fail(f"job {job_id} still {job['state']} after {timeout} s")


def test_mjtf_job_gives_the_library_numbers(client, auth):
    spec = {"zeta0s": [0.88, 0.94], "trials": 40, "cap": 200, "seed": 5, "guess": {"xdot": -0.93, "ydot": -0.2}}
    job = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert job.status_code == 202 and job.json()["total"] == 80
    assert _wait(client, job.json()["id"])["state"] == "done"
    levels = client.get(f"/api/v1/jobs/{job.json()['id']}/results").json()["levels"]
    study = mjtf_study(
        get_preset("paper").to_model(), math.radians(30), [0.88, 0.94], noise=NoiseModel(), trials=40, cap=200, seed=5,
        guess=(-0.93, -0.2),
    )  # fmt: skip
    for got, expected in zip(levels, study.levels, strict=True):
        assert got["trials"] == 40
        assert got["mean"] == pytest.approx(float(np.mean(expected.jumps)))
        assert got["outcomes"] == expected.histogram()


def test_job_progress_streams_as_server_sent_events(client, auth):
    spec = {"zeta0s": [0.88, 0.9], "trials": 96, "cap": 300, "guess": {"xdot": -0.93, "ydot": -0.2}}
    job_id = client.post("/api/v1/jobs", json=spec, headers=auth).json()["id"]
    events = []
    with client.stream("GET", f"/api/v1/jobs/{job_id}/events") as stream:
        assert stream.headers["content-type"].startswith("text/event-stream")
        for line in stream.iter_lines():
            if line.startswith("data: "):
                events.append(json.loads(line.removeprefix("data: ")))
    counts = [event["completed"] for event in events]
    assert events[-1]["state"] == "done" and counts[-1] == 192
    assert counts == sorted(counts), "progress only grows"
    assert client.get("/api/v1/jobs/999/events").status_code == 404


def test_cancel_stops_a_job(client, auth):
    spec = {"zeta0s": [0.84, 0.86, 0.88], "trials": 3000, "cap": 2000, "guess": {"xdot": -0.93, "ydot": 0.2}}
    job_id = client.post("/api/v1/jobs", json=spec, headers=auth).json()["id"]
    assert client.post(f"/api/v1/jobs/{job_id}/cancel").status_code == 401
    client.post(f"/api/v1/jobs/{job_id}/cancel", headers=auth)
    job = _wait(client, job_id)
    assert job["state"] == "cancelled" and job["completed"] < job["total"]


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        ({"zeta0s": [], "trials": 8}, "zeta0s"),
        ({"zeta0s": [0.9], "trials": -1}, "trials"),
        ({"zeta0s": [0.9], "trials": 10**9}, "trials"),
        ({"zeta0s": [0.9, 0.9]}, "zeta0s"),
    ],
)
def test_bad_job_specs_are_refused_before_any_work(client, auth, spec, field):
    response = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert response.status_code == 422 and any(field in e["loc"] for e in response.json()["detail"])
    assert client.get("/api/v1/jobs").json()["items"] == []


def test_quick_fixed_point(client):
    body = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "guess": {"xdot": -0.9, "ydot": -0.2}}
    gait = client.post("/api/v1/sim/fixed-point", json=body).json()
    assert gait["period"] == 1 and gait["stable"] and gait["max_abs_eigenvalue"] == pytest.approx(0.8486, abs=1e-4)


def test_concurrent_clients_do_not_corrupt_state(client, auth):
    from concurrent.futures import ThreadPoolExecutor

    experiment = client.post("/api/v1/experiments", json={"name": "busy"}, headers=auth).json()["id"]

    def create(i):
        body = RUN | {"experiment_id": experiment, "jumps": 2, "tags": [f"t{i % 3}"]}
        return client.post("/api/v1/runs", json=body, headers=auth).status_code

    with ThreadPoolExecutor(8) as pool:
        codes = list(pool.map(create, range(40)))
    assert codes == [201] * 40
    assert client.get(f"/api/v1/experiments/{experiment}").json()["runs"] == 40
    counts = {g["key"]: g["runs"] for g in client.get("/api/v1/runs/aggregate", params={"by": "tag"}).json()["groups"]}
    assert counts == {"t0": 14, "t1": 13, "t2": 13}


def test_sweep_basin_and_gait_search_jobs(client, auth):
    specs = {
        "sweep": {"kind": "sweep", "zeta0_low": 0.9, "zeta0_high": 0.97, "steps": 4, "basin_grid": 8,
                  "guess": {"xdot": -0.93, "ydot": -0.2}},
        "basin": {"kind": "basin", "controls": [{"psi0_deg": 30, "zeta0": 0.9}], "grid": 12, "jumps": 30,
                  "guess": {"xdot": -0.9, "ydot": -0.2}},
        "gaits": {"kind": "gaits", "controls": [{"psi0_deg": 30, "zeta0": 0.9}], "grid": 2},
    }  # fmt: skip
    ids = {kind: client.post("/api/v1/jobs", json=spec, headers=auth).json()["id"] for kind, spec in specs.items()}
    results = {}
    for kind, job_id in ids.items():
        job = _wait(client, job_id)
        assert job["state"] == "done" and job["completed"] == job["total"], job
        results[kind] = client.get(f"/api/v1/jobs/{job_id}/results").json()["result"]
    assert len(results["sweep"]["points"]) == 4 and len(results["sweep"]["in_place_zeta0"]) == 1
    assert sum(results["basin"]["counts"].values()) == 144 and results["basin"]["counts"]["converged"] > 0
    assert results["gaits"]["gaits"][0]["period"] == 1


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        ({"kind": "sweep", "zeta0_low": 0.95, "zeta0_high": 0.9}, "sweep"),
        ({"kind": "basin", "controls": [{"psi0_deg": 30, "zeta0": 0.9}], "grid": 10**6}, "grid"),
        ({"kind": "atlas"}, "kind"),
    ],
)
def test_bad_study_specs_are_a_422(client, auth, spec, field):
    response = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert response.status_code == 422, response.text
    assert field in str(response.json()["detail"])


def test_sorting_best_first_pages_by_offset(client, auth):
    for zeta0 in (0.9, 0.84, 0.94, 0.88):
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}]}
        client.post("/api/v1/runs", json=body, headers=auth)
    first = client.get("/api/v1/runs", params={"sort": "-climb", "limit": 3}).json()
    climbs = [run["climb"] for run in first["items"]]
    assert climbs == sorted(climbs, reverse=True) and first["next_cursor"] == 3
    rest = client.get("/api/v1/runs", params={"sort": "-climb", "limit": 3, "offset": 3}).json()
    assert len(rest["items"]) == 1 and rest["next_cursor"] is None and rest["items"][0]["climb"] < climbs[-1]
    assert client.get("/api/v1/runs", params={"sort": "password"}).status_code == 422


def test_quick_trajectory(client):
    body = {k: RUN[k] for k in ("controls", "start")} | {"jumps": 2, "rate": 50}
    path = client.post("/api/v1/sim/trajectory", json=body).json()
    assert path["units"] == "nondimensional" and len(path["touchdown_times"]) == 3
    assert len(path["columns"]["x"]) == len(path["columns"]["time"]) > 50 and path["failure"] is None


def test_run_with_fixed_point_and_retagging(client, auth):
    run = client.post("/api/v1/runs", json=RUN | {"fixed_point": True}, headers=auth).json()
    gait = run["results"]["fixed_point"]
    assert gait["found"] and gait["period"] == 1 and gait["max_abs_eigenvalue"] == pytest.approx(0.8486, abs=1e-4)
    lost = client.post(
        "/api/v1/runs", json=RUN | {"fixed_point": True, "start": {"xdot": -0.3, "ydot": 5.0}}, headers=auth
    ).json()
    assert lost["results"]["fixed_point"]["found"] is False and lost["failure_code"] == "no_flight"
    retagged = client.patch(f"/api/v1/runs/{run['id']}", json={"tags": ["keep", "keep", "best"]}, headers=auth)
    assert retagged.json()["tags"] == ["best", "keep"]
    assert client.patch(f"/api/v1/runs/{run['id']}", json={"climb": 9}, headers=auth).status_code == 422
    assert run["notes"] == ""
    noted = client.patch(f"/api/v1/runs/{run['id']}", json={"notes": "left foot slipped once"}, headers=auth).json()
    assert noted["notes"] == "left foot slipped once" and noted["tags"] == ["best", "keep"], "tags left out stay"
    assert client.get(f"/api/v1/runs/{run['id']}").json()["notes"] == "left foot slipped once"
    too_long = client.patch(f"/api/v1/runs/{run['id']}", json={"notes": "x" * 100_001}, headers=auth)
    assert too_long.status_code == 422 and "notes" in too_long.text
