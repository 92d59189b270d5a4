"""The real service the client's tests share: ``parkour serve`` in a subprocess on a free port with a
fresh SQLite data directory, started once for the session (tests/helpers.py), and what is put in it
once for every module that reads it (test_client, test_jobs, test_frames)."""

from __future__ import annotations

import pytest

from parkourlab import Client
from tests.helpers import start_service, stop_processes

START = (-0.93, -0.17)  # section state (xdot, ydot) [sqrt(g l0)] near the paper's period-1 gait
ZETA0S = [0.84, 0.85, 0.86, 0.87, 0.88, 0.89, 0.9]  # seven runs: more than two pages of three
QUICK_ZETA0S = [0.88, 0.9]
QUICK_MJTF = {"trials": 4, "cap": 30, "seed": 1}  # 2 levels x 4 trials of at most 30 jumps: a second or two
WAIT_TIMEOUT = 120.0  # [s] for a quick job on a slow, shared machine


@pytest.fixture(scope="session")
def service(tmp_path_factory):
    """``(url, token)`` of a running service with an empty store."""
    data_dir = tmp_path_factory.mktemp("client") / "data"
    process = start_service(data_dir, 0, "--no-view")
    try:
        yield f"http://127.0.0.1:{process.port}", (data_dir / "api_token").read_text().strip()
    finally:
        stop_processes(process)


@pytest.fixture(scope="session")
def client(service):
    url, token = service
    with Client(url, token=token) as client:
        yield client


@pytest.fixture(scope="session")
def paging_runs(client) -> list[dict]:
    """Seven runs tagged ``paging`` (one per zeta0 of ZETA0S) in an experiment of their own."""
    experiment = client.create_experiment("paging", description="client tests")
    return [
        client.create_run([(30, zeta0)], START, jumps=5, tags=["paging"], experiment_id=experiment["id"])
        for zeta0 in ZETA0S
    ]


@pytest.fixture(scope="session")
def quick_job(client) -> dict:
    """A small MJTF job (QUICK_ZETA0S x QUICK_MJTF), waited for until done."""
    job = client.submit_mjtf(QUICK_ZETA0S, **QUICK_MJTF)
    return client.wait(job, timeout=WAIT_TIMEOUT, progress=True)
