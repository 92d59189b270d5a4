"""Calibrations through the API: fitted in the compute worker, stored as a preset, listed, read,
deleted; only with the token; bad requests name their field (backend/api/routes/calibrations.py)."""

import pytest

from sim_core.model.noise import NoiseModel
from sim_core.world.files import world_from_document
from tests.tracked_climbs import Truth, store_varied_runs

TRUTH = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))


def test_a_calibration_is_fitted_stored_listed_and_deleted(client, auth):
    with client.app.state.sessions() as session:
        runs = store_varied_runs(session, TRUTH, noise=NoiseModel(pitch_drift_deg=0.2), jumps=30)
    body = {"runs": runs, "name": "table.v1"}
    assert client.post("/api/v1/calibrations", json=body).status_code == 401, "a change needs the token"
    response = client.post("/api/v1/calibrations", json=body, headers=auth)
    assert response.status_code == 201, response.text
    fitted = response.json()
    assert abs(fitted["params"]["alpha"] - 72.0) < 3 * fitted["stderr"]["alpha"]
    assert fitted["preset"]["runs"] == runs and fitted["rms_residual_after"] < fitted["rms_residual_before"]
    assert client.get("/api/v1/calibrations/table.v1").json() == fitted
    assert [item["preset"]["name"] for item in client.get("/api/v1/calibrations").json()["items"]] == ["table.v1"]

    compared = client.get(f"/api/v1/runs/{runs[2]}/touchdowns", params={"preset": "table.v1"}).json()
    rows, rms = compared["touchdowns"], compared["rms"]
    assert len(rows) > 20 and {"measured", "paper", "calibrated", "paper_residual", "calibrated_residual"} <= set(
        rows[0]
    )
    assert rows[0]["paper_residual"]["xdot"] == pytest.approx(rows[0]["paper"]["xdot"] - rows[0]["measured"]["xdot"])
    for channel in ("xdot", "ydot", "rise"):
        assert rms["calibrated"][channel] < 0.5 * rms["paper"][channel], (channel, rms)
    plain = client.get(f"/api/v1/runs/{runs[2]}/touchdowns").json()
    assert plain["preset"] is None and plain["touchdowns"][0]["calibrated"] is None
    assert client.get(f"/api/v1/runs/{runs[2]}/touchdowns", params={"preset": "nothing"}).status_code == 404
    assert client.get(f"/api/v1/runs/{runs[2]}/touchdowns", params={"preset": "a b"}).status_code == 422

    # The preset by name, wherever a model is asked for: resolved to its base and fitted numbers.
    query = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.9, "ydot": -0.2}, "jumps": 3}
    by_name = client.post("/api/v1/sim/map", json=query | {"model": {"preset": "table.v1"}}).json()
    numbers = {name: fitted["params"][name] for name in ("alpha", "c_zeta", "c_psi")}
    by_numbers = client.post("/api/v1/sim/map", json=query | {"model": numbers}).json()
    assert by_name["rises"] == pytest.approx(by_numbers["rises"], rel=1e-9)
    run = client.post("/api/v1/runs", json=query | {"model": {"preset": "table.v1"}}, headers=auth).json()
    assert run["model"]["alpha"] == pytest.approx(fitted["params"]["alpha"])
    unknown = client.post("/api/v1/sim/map", json=query | {"model": {"preset": "nothing"}})
    assert unknown.status_code == 422 and unknown.json()["detail"][0]["loc"] == ["body", "model.preset"]
    assert "known presets: paper, table.v1" in unknown.json()["detail"][0]["msg"]

    again = client.post("/api/v1/calibrations", json=body, headers=auth)
    assert again.status_code == 409 and "exists" in again.json()["detail"]
    assert client.delete("/api/v1/calibrations/table.v1").status_code == 401
    assert client.delete("/api/v1/calibrations/table.v1", headers=auth).status_code == 204
    assert client.get("/api/v1/calibrations/table.v1").status_code == 404


def test_bad_calibration_requests_name_what_is_wrong(client, auth):
    def error(body):
        response = client.post("/api/v1/calibrations", json=body, headers=auth)
        return response.status_code, response.json()["detail"]

    status, detail = error({"runs": [], "name": "x"})
    assert status == 422 and detail[0]["loc"] == ["body", "runs"]
    status, detail = error({"runs": [1], "name": "no spaces"})
    assert status == 422 and detail[0]["loc"] == ["body", "name"]
    assert error({"runs": [1], "name": "paper"})[0] == 422, "a built-in preset's name is taken"
    assert error({"runs": [999], "name": "x"}) == (404, "run 999 does not exist")
    run = client.post(
        "/api/v1/runs", json={"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.9, "ydot": -0.2}},
        headers=auth,
    ).json()  # fmt: skip
    status, detail = error({"runs": [run["id"]], "name": "x"})
    assert status == 409 and "robot and replay runs" in detail
    assert client.get(f"/api/v1/runs/{run['id']}/touchdowns").status_code == 409
    assert client.get("/api/v1/calibrations/nothing").status_code == 404


def test_a_run_in_a_world_is_compared_in_it_and_refused_by_calibration(client, auth):
    """/touchdowns of a run in a stored world: each touchdown the model's jump in that world (the
    compute worker given the world), the world named; calibrating it is a 422 naming the run."""
    from sim_core.world.climb import climb_world
    from tests.backend.services.test_run_prediction import GAIT, JUMPS, ROBOT, START, store_run, tracked
    from tests.backend.services.test_touchdowns_in_worlds import CHANNELS, TIGHT

    world = client.post("/api/v1/worlds", json={"name": "narrowing chute", "named": "narrowing"}, headers=auth).json()
    chute = world_from_document(world["world"], ROBOT.leg_length)
    with client.app.state.sessions() as session:
        run = store_run(session, tracked(climb_world(ROBOT.to_model(), chute, GAIT, START, JUMPS)), world["id"]).id
    compared = client.get(f"/api/v1/runs/{run}/touchdowns").json()
    assert compared["world"] == {"id": world["id"], "name": "narrowing chute"} and len(compared["touchdowns"]) > 4
    assert max(abs(row["paper_residual"][channel]) for row in compared["touchdowns"] for channel in CHANNELS) < TIGHT
    refused = client.post("/api/v1/calibrations", json={"runs": [run], "name": "x"}, headers=auth)
    assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == ["body", "runs"]
    assert f"run {run} climbed world {world['id']}" in refused.json()["detail"][0]["msg"]
