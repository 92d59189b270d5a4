"""The service on PostgreSQL end to end (DATABASE_URL switches it with no code change).

Every store and API test runs on PostgreSQL too (the ``database_url`` fixture); this one is the
whole path in one place — migrations, a run, a filtered list, an MJTF job with its trials, an
aggregate — and checks that both databases give the same JSON, types included: a number stays a
number (PostgreSQL's AVG is a NUMERIC, which the driver hands over as a Decimal).
"""

import time

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.settings import Settings

RUN = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.93, "ydot": -0.17}, "tags": ["pg"]}
JOB = {"zeta0s": [0.9], "trials": 40, "cap": 100, "guess": {"xdot": -0.93, "ydot": -0.2}, "seed": 3}


def _session_answers(settings: Settings, compute) -> dict:
    """What a short session of a lab member's calls answers, keyed by call (volatile fields dropped)."""
    with TestClient(create_app(settings, compute=compute)) as client:
        headers = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
        answers = {"health": client.get("/api/v1/health").json()["database"]}
        answers["run"] = client.post("/api/v1/runs", json=RUN, headers=headers).json()
        answers["list"] = client.get("/api/v1/runs", params={"tag": "pg", "zeta0_min": 0.85}).json()
        job_id = client.post("/api/v1/jobs", json=JOB, headers=headers).json()["id"]
        deadline = time.monotonic() + 60
        while client.get(f"/api/v1/jobs/{job_id}").json()["state"] != "done":
            assert time.monotonic() < deadline, "the job did not finish within a minute"
            time.sleep(0.05)
        answers["results"] = client.get(f"/api/v1/jobs/{job_id}/results").json()
        answers["by tag"] = client.get("/api/v1/runs/aggregate", params={"by": "tag"}).json()
        answers["by zeta0"] = client.get("/api/v1/runs/aggregate", params={"by": "zeta0", "bins": 4}).json()
    for record in [answers["run"], *answers["list"]["items"], answers["results"]["job"]]:
        for volatile in ("created_at", "started_at", "finished_at", "duration_s", "code_version"):
            record.pop(volatile, None)
    return answers


def _types(value):
    """The JSON value's shape with every leaf replaced by its type's name."""
    if isinstance(value, dict):
        return {key: _types(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_types(item) for item in value]
    return type(value).__name__


@pytest.mark.slow
def test_postgres_and_sqlite_answer_the_same_json(tmp_path, postgres, compute):
    with postgres.fresh() as url:
        on_postgres = _session_answers(Settings.from_environment(tmp_path / "pg", url), compute)
    on_sqlite = _session_answers(Settings.from_environment(tmp_path / "sqlite"), compute)
    assert (on_postgres.pop("health"), on_sqlite.pop("health")) == ("postgresql", "sqlite")
    assert on_postgres["results"]["levels"][0]["trials"] == 40
    assert on_postgres["by tag"]["groups"][0]["key"] == "pg"
    assert _types(on_postgres) == _types(on_sqlite)
    assert _close(on_postgres, on_sqlite), (on_postgres, on_sqlite)


def _close(a, b) -> bool:
    """Equal JSON, floats to 1e-9 (the databases may sum in different orders)."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_close(a[key], b[key]) for key in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float):
        return a == pytest.approx(b, rel=1e-9, abs=1e-12)
    return a == b
