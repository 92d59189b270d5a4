"""Batch jobs through the API: the library's numbers, progress events, cancel (backend/api/routes/jobs.py)."""

import json
import math
import time

import numpy as np
import pytest

from sim_core import get_preset
from sim_core.model.noise import NoiseModel
from sim_core.robustness.mjtf import mjtf_study


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
    results = client.get(f"/api/v1/jobs/{job.json()['id']}/results").json()
    assert results["partial"] is False and results["missing_zeta0s"] == []
    levels = results["levels"]
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
    # Its results say partial and list only the levels that have trials: a level that never ran
    # is not a level whose robot fell at once (the chart used to plot it at MJTF = 0).
    results = client.get(f"/api/v1/jobs/{job_id}/results").json()
    assert results["partial"] is True
    assert all(level["trials"] > 0 for level in results["levels"])
    listed = [level["zeta0"] for level in results["levels"]] + results["missing_zeta0s"]
    assert sorted(listed) == [0.84, 0.86, 0.88] and results["missing_zeta0s"], "3000 x 3 trials: cancelled early"


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
        ({"kind": "no-such-kind"}, "kind"),
    ],
)
def test_bad_study_specs_are_a_422(client, auth, spec, field):
    response = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert response.status_code == 422, response.text
    assert field in str(response.json()["detail"])


@pytest.mark.parametrize(
    ("spec", "formula"),
    [
        ({"zeta0s": [0.8 + 0.001 * k for k in range(100)], "trials": 100_000, "cap": 100_000}, "levels x trials x cap"),
        ({"kind": "basin", "controls": [{"psi0_deg": 30, "zeta0": 0.9}], "grid": 1000, "jumps": 1000}, "grid"),
        ({"kind": "sweep", "steps": 500, "basin_grid": 200, "basin_jumps": 1000}, "basin_grid"),
    ],
)
def test_jobs_over_the_work_budget_are_a_422_naming_the_limit(client, auth, spec, formula):
    response = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert response.status_code == 422, response.text
    message = " ".join(error["msg"] for error in response.json()["detail"])
    assert "over the limit of 5e+08" in message and formula in message, message
    assert client.get("/api/v1/jobs").json()["items"] == [], "nothing stored, nothing queued"


def test_jobs_list_by_experiment(client, auth):
    experiment = client.post("/api/v1/experiments", json={"name": "e"}, headers=auth).json()["id"]
    spec = {"zeta0s": [0.9], "trials": 1, "cap": 2}
    filed = client.post("/api/v1/jobs", json=spec | {"experiment_id": experiment}, headers=auth).json()["id"]
    client.post("/api/v1/jobs", json=spec, headers=auth)
    listed = client.get("/api/v1/jobs", params={"experiment_id": experiment}).json()["items"]
    assert [job["id"] for job in listed] == [filed]
    assert len(client.get("/api/v1/jobs").json()["items"]) == 2
    assert client.get("/api/v1/jobs", params={"experiment_id": 0}).status_code == 422


def test_jobs_list_by_kind_and_world(client, auth):
    world = client.post("/api/v1/worlds", json={"name": "walls", "named": "parallel"}, headers=auth).json()["id"]
    other = client.post("/api/v1/worlds", json={"name": "steps", "named": "staircase"}, headers=auth).json()["id"]
    client.post("/api/v1/jobs", json={"zeta0s": [0.9], "trials": 1, "cap": 2}, headers=auth)
    plan = {"kind": "plan", "world_id": world, "goal_height_m": 0.3}
    planned = client.post("/api/v1/jobs", json=plan, headers=auth).json()["id"]
    elsewhere = client.post("/api/v1/jobs", json=plan | {"world_id": other}, headers=auth).json()["id"]
    page = client.get("/api/v1/jobs", params={"kind": "plan"}).json()
    assert [job["id"] for job in page["items"]] == [elsewhere, planned] and page["total"] == 2
    in_world = client.get("/api/v1/jobs", params={"kind": "plan", "world_id": world}).json()["items"]
    assert [job["id"] for job in in_world] == [planned]
    assert client.get("/api/v1/jobs", params={"kind": "mjtf", "world_id": world}).json()["items"] == []
    refused = client.get("/api/v1/jobs", params={"kind": "plans"})
    assert refused.status_code == 422 and refused.json()["detail"][0]["loc"] == ["query", "kind"]
    assert "'plan'" in refused.json()["detail"][0]["msg"], "the message names the kinds allowed"


def test_past_the_queue_budget_a_job_is_a_429_naming_it(client, auth, monkeypatch):
    from backend.services import job_queue

    monkeypatch.setattr(job_queue, "QUEUE_BUDGET_JUMPS", 100)
    body = {"zeta0s": [0.9], "trials": 4, "cap": 100}
    refused = client.post("/api/v1/jobs", json=body, headers=auth | {"X-Parkour-Client": "sweep-script"})
    assert refused.status_code == 429
    assert refused.json()["detail"].startswith("the job queue is full: this job's 400 jumps at its worst")
    assert client.get("/api/v1/jobs").json()["items"] == []


def test_the_submitter_is_the_tokens_person_and_the_header_labels_the_tool(client, auth):
    body = {"zeta0s": [0.9], "trials": 2, "cap": 20}
    named = client.post("/api/v1/jobs", json=body, headers=auth | {"X-Parkour-Client": "panel"}).json()
    unnamed = client.post("/api/v1/jobs", json=body, headers=auth).json()
    assert (named["submitted_by"], named["submitted_via"]) == ("lab", "panel"), "api_token is the lab's"
    assert (unnamed["submitted_by"], unnamed["submitted_via"]) == ("lab", None)
    bad = client.post("/api/v1/jobs", json=body, headers=auth | {"X-Parkour-Client": "<script>"})
    assert bad.status_code == 422 and bad.json()["detail"][0]["loc"] == ["header", "X-Parkour-Client"]


def test_a_control_study_job_gives_the_studys_numbers_and_its_plots(client, auth):
    """The job is parkour control-study's study (experiments/control_study.run) on the same seeds,
    with the panel's plots beside the command line's JSON."""
    from experiments.control_study import Config, run

    spec = {"kind": "control-study", "controllers": ["pid", "lqr"], "target_m": 0.5, "jumps": 80, "seeds": 12,
            "seed0": 4, "noise": {"pitch_drift_deg": 2.0}}  # fmt: skip
    job = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert job.status_code == 202, job.text
    # 24 closed-loop climbs of 80 jumps: 60 s ran out on a machine loaded 4x (a hang guard, not a speed)
    assert _wait(client, job.json()["id"], timeout=240.0)["state"] == "done"
    result = client.get(f"/api/v1/jobs/{job.json()['id']}/results").json()["result"]
    robot = get_preset("paper")
    config = Config(controllers=("pid", "lqr"), target_m=0.5, jumps=80, seeds=12, seed0=4,
                    noise=NoiseModel(pitch_drift_deg=2.0))  # fmt: skip
    expected = run(robot.to_model(), robot.leg_length, config)
    for got, want in zip(result["controllers"], expected.to_dict()["controllers"], strict=True):
        assert got.pop("us_per_jump") > 0 and want.pop("us_per_jump") > 0  # timed: not the same twice
        assert got == want
    assert result["seeds"] == [4, 12] and result["noise"]["pitch_drift_deg"] == 2.0
    assert [plot["name"] for plot in result["plots"]["controllers"]] == ["pid", "lqr"]
    assert result["plots"]["controllers"][0]["failure_curve"]["failures"][-1] == result["controllers"][0]["failures"]


def test_an_mfpt_job_gives_the_chains_numbers(client, auth):
    """The job is parkour mfpt's computation (sim_core.robustness.mfpt) on the same grid, to the last digit."""
    from sim_core.model.controls import LegControl
    from sim_core.robustness.mfpt import mfpt
    from sim_core.robustness.mfpt_grid import ChainGrid

    start = {"xdot": -0.9339, "ydot": -0.1661}
    spec = {"kind": "mfpt", "zeta0": 0.9, "start": start, "grid": 8, "pitch_spacing": 2.0,
            "noise": {"pitch_drift_deg": 0.0, "velocity": 0.1}}  # fmt: skip
    job = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert job.status_code == 202, job.text
    assert _wait(client, job.json()["id"], timeout=300.0)["state"] == "done"  # a first compile of the chain's kernels
    result = client.get(f"/api/v1/jobs/{job.json()['id']}/results").json()["result"]
    expected = mfpt(get_preset("paper").to_model(), LegControl(math.radians(30.0), 0.9),
                    NoiseModel(pitch_drift_deg=0.0, velocity=0.1), start=(start["xdot"], start["ydot"]),
                    grid=ChainGrid(velocity_nodes=8, pitch_spacing=2.0, max_pairs=600_000)).to_dict()  # fmt: skip
    for key in ("mfpt_jumps", "lambda2", "discretisation_error", "cells"):
        assert result[key] == pytest.approx(expected[key], rel=1e-9), key
    assert result["controls"]["zeta0"] == 0.9 and result["noise"]["velocity"] == 0.1


def test_a_viability_job_gives_the_engines_kernel_and_every_viable_pair(client, auth):
    """The job is parkour viability's computation on the same grid; its packed pairs unpack to the
    engine's own."""
    import base64

    from sim_core.viability.engine import compute_viability
    from sim_core.viability.grid import section_grid
    from sim_core.viability.step_map import section_step_map

    spec = {"kind": "viability", "states": 8, "actions": 3, "zeta0_low": 0.8}
    job = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert job.status_code == 202, job.text
    assert _wait(client, job.json()["id"], timeout=300.0)["state"] == "done"
    result = client.get(f"/api/v1/jobs/{job.json()['id']}/results").json()["result"]
    model = get_preset("paper").to_model()
    expected = compute_viability(section_step_map(model), section_grid(states=8, actions=3, zeta0_range=(0.8, 0.98)))
    assert result["kernel"] == expected.kernel.tolist() and result["measure"] == expected.measure.tolist()
    bits = np.unpackbits(np.frombuffer(base64.b64decode(result["viable_pairs"]), dtype=np.uint8))
    shape = tuple(result["viable_pairs_shape"])
    assert shape == (8, 8, 3, 3)
    assert np.array_equal(bits[: np.prod(shape)].reshape(shape).astype(bool), expected.viable_pairs)
    assert result["action_axes"]["zeta0"][0] == 0.8


@pytest.mark.parametrize(
    ("change", "field", "says"),
    [
        ({"controllers": ["pid", "mpc"]}, "controllers", "must be among pid"),
        ({"controllers": ["lqr", "lqr"]}, "controllers", "names a controller twice"),
        ({"controllers": []}, "controllers", "at least 1"),
        ({"target_m": 0.0}, "target_m", "greater than 0"),
        ({"target_m": 2.5}, "target_m", "less than or equal to 2"),
        ({"psi0_deg": 80}, "psi0_deg", "less than or equal to 60"),
        ({"seeds": 0}, "seeds", "greater than or equal to 1"),
        ({"jumps": 100_000, "seeds": 100_000}, "control-study", "controllers x seeds x jumps"),
        ({"noise": {"pitch_drift_deg": -1}}, "pitch_drift_deg", "greater than or equal to 0"),
    ],
)
def test_bad_control_studies_are_a_422_naming_the_field(client, auth, change, field, says):
    response = client.post("/api/v1/jobs", json={"kind": "control-study", **change}, headers=auth)
    assert response.status_code == 422, response.text
    errors = response.json()["detail"]
    assert any(field in map(str, error["loc"]) and says in error["msg"] for error in errors), errors
    assert client.get("/api/v1/jobs").json()["items"] == []


def test_a_controllers_mfpt_job_gives_the_splittings_numbers_for_its_seed(client, auth):
    """The job is parkour mfpt --controller's computation (experiments.loop_mfpt.run) with the same
    options and seed, to the last digit; its progress counts splitting runs."""
    from experiments.loop_mfpt import Config, run
    from sim_core.robustness.splitting import SplittingOptions

    spec = {"kind": "loop-mfpt", "controller": "lqr", "target_m": 0.55, "replicas": 20, "runs": 2, "seed": 3,
            "noise": {"velocity": 0.05, "pitch_drift_deg": 0.0}}  # fmt: skip
    job = client.post("/api/v1/jobs", json=spec, headers=auth)
    assert job.status_code == 202, job.text
    done = _wait(client, job.json()["id"], timeout=300.0)  # a first compile of the loop's kernels
    assert done["state"] == "done" and done["completed"] == done["total"] == 2, done
    result = client.get(f"/api/v1/jobs/{job.json()['id']}/results").json()["result"]
    preset = get_preset("paper")
    config = Config(controller="lqr", target_m=0.55, noise=NoiseModel(velocity=0.05, pitch_drift_deg=0.0),
                    options=SplittingOptions(replicas=20, runs=2, seed=3))  # fmt: skip
    expected = run(preset.to_model(), preset.leg_length, config)
    for key in ("mfpt_jumps", "lambda2", "lambda2_jumps"):
        assert result[key] == pytest.approx(expected[key], rel=1e-9), key
    assert result["ci95"][0] == pytest.approx(expected["ci95"][0], rel=1e-9)
    assert result["ci95"][1:] == expected["ci95"][1:] == [None], "two runs: a t interval open above"
    assert result["splitting"]["probabilities"] == pytest.approx(expected["splitting"]["probabilities"], rel=1e-9)
    assert result["method"] == "splitting" and result["controller"] == "lqr" and result["splitting"]["seed"] == 3


@pytest.mark.parametrize(
    ("change", "field", "says"),
    [
        ({"controller": "mpc"}, "controller", "'pid', 'pid-pitch', 'lqr', 'deadbeat' or 'placement'"),
        ({"noise": {"velocity": 0.05, "pitch_drift_deg": 0.5}}, "pitch_drift_deg", "must be 0 for a controller's MFPT"),
        ({"replicas": 1000, "runs": 64}, "loop-mfpt", "replicas x runs must be at most"),
    ],
)
def test_bad_controller_mfpts_are_a_422_naming_the_field_never_a_500(client, auth, change, field, says):
    response = client.post("/api/v1/jobs", json={"kind": "loop-mfpt", **change}, headers=auth)
    assert response.status_code == 422, response.text
    errors = response.json()["detail"]
    assert any(field in map(str, error["loc"]) and says in error["msg"] for error in errors), errors
    assert client.get("/api/v1/jobs").json()["items"] == []


def test_a_job_in_a_world_not_stored_is_a_404_and_a_reversed_range_a_422_naming_it(client, auth):
    """The reach job (backend/jobs/reach.py) as the API takes it: its world looked up when accepted."""
    missing = client.post("/api/v1/jobs", json={"kind": "reach", "world_id": 999}, headers=auth)
    assert missing.status_code == 404 and "world" in missing.text, missing.text
    world = client.post("/api/v1/worlds", json={"name": "stairs", "named": "staircase"}, headers=auth).json()
    reversed_range = {"kind": "reach", "world_id": world["id"], "psi0_range": [40, 20]}
    refused = client.post("/api/v1/jobs", json=reversed_range, headers=auth)
    assert refused.status_code == 422, refused.text
    (error,) = refused.json()["detail"]
    assert error["loc"][-1] == "psi0_range" and "low below high, got [40, 20]" in error["msg"]
    assert client.get("/api/v1/jobs").json()["items"] == [], "nothing stored, nothing queued"
    small = {"kind": "reach", "world_id": world["id"], "psi0_steps": 2, "zeta0_steps": 2, "jumps": 5}
    job = client.post("/api/v1/jobs", json=small, headers=auth)
    assert job.status_code == 202 and job.json()["world_id"] == world["id"], job.text
    done = _wait(client, job.json()["id"])
    assert done["state"] == "done" and done["completed"] == done["total"] == 1
    result = client.get(f"/api/v1/jobs/{done['id']}/results").json()["result"]
    assert result["world"] == "stairs" and len(result["highest"]) == 2 and sum(result["outcomes"].values()) == 4
