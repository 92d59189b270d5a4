"""A job on a Dask cluster (LocalCluster of worker processes): same trials as in-process."""

import dataclasses
import time

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app

pytestmark = pytest.mark.slow  # starts worker processes

SPEC = {"zeta0s": [0.88, 0.92], "trials": 70, "cap": 300, "seed": 9, "guess": {"xdot": -0.93, "ydot": -0.2}}


@pytest.fixture(scope="module")
def scheduler():
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        yield cluster.scheduler_address


def _run_job(settings) -> list[dict]:
    with TestClient(create_app(settings)) as client:
        token = (settings.data_dir / "api_token").read_text().strip()
        job_id = client.post("/api/v1/jobs", json=SPEC, headers={"Authorization": f"Bearer {token}"}).json()["id"]
        deadline = time.monotonic() + 120
        while (job := client.get(f"/api/v1/jobs/{job_id}").json())["state"] != "done":
            assert job["state"] in ("queued", "running") and time.monotonic() < deadline, job
            time.sleep(0.05)
        return client.get(f"/api/v1/jobs/{job_id}/results").json()["levels"]


def test_job_on_the_cluster_equals_in_process(settings, tmp_path, scheduler):
    local = _run_job(settings)
    remote_settings = dataclasses.replace(
        settings, data_dir=tmp_path / "remote", database_url=f"sqlite:///{tmp_path / 'remote.sqlite3'}",
        dask_address=scheduler,
    )  # fmt: skip
    assert _run_job(remote_settings) == local

    from distributed import Client

    with Client(scheduler) as client:
        prefixes = client.run_on_scheduler(lambda dask_scheduler: list(dask_scheduler.task_prefixes))
    assert "run_trials" in prefixes, "the chunks ran on the cluster"
