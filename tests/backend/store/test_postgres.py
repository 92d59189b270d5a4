"""The same store on PostgreSQL, when a server is given (``PARKOUR_TEST_POSTGRES_URL``).

DATABASE_URL switches the service to PostgreSQL with no code change; this test proves it against
a real server: migrations, a run, a filtered list, an MJTF job with its trials. It drops and
recreates the schema of the database it is given, so point it at a scratch database, e.g.
``postgresql+psycopg://postgres@127.0.0.1:55432/parkourlab``. Without the variable it is skipped
(CI machines have no PostgreSQL server).
"""

import os
import time

import pytest
from fastapi.testclient import TestClient
from sqlalchemy import text

from backend.api.app import create_app
from backend.settings import Settings
from backend.store.database import make_engine

URL = os.environ.get("PARKOUR_TEST_POSTGRES_URL")
pytestmark = pytest.mark.skipif(not URL, reason="set PARKOUR_TEST_POSTGRES_URL to a scratch PostgreSQL database")


def test_service_on_postgres(tmp_path):
    engine = make_engine(URL)
    with engine.begin() as connection:
        connection.execute(text("DROP SCHEMA public CASCADE; CREATE SCHEMA public"))
    engine.dispose()
    settings = Settings.from_environment(tmp_path / "data", URL)
    with TestClient(create_app(settings)) as client:
        headers = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
        assert client.get("/api/v1/health").json()["database"] == "postgresql"
        run = {"controls": [{"psi0_deg": 30, "zeta0": 0.9}], "start": {"xdot": -0.93, "ydot": -0.17}, "tags": ["pg"]}
        assert client.post("/api/v1/runs", json=run, headers=headers).status_code == 201
        assert len(client.get("/api/v1/runs", params={"tag": "pg", "zeta0_min": 0.85}).json()["items"]) == 1
        spec = {"zeta0s": [0.9], "trials": 40, "cap": 100, "guess": {"xdot": -0.93, "ydot": -0.2}}
        job_id = client.post("/api/v1/jobs", json=spec, headers=headers).json()["id"]
        deadline = time.monotonic() + 60
        while client.get(f"/api/v1/jobs/{job_id}").json()["state"] != "done":
            assert time.monotonic() < deadline
            time.sleep(0.05)
        assert client.get(f"/api/v1/jobs/{job_id}/results").json()["levels"][0]["trials"] == 40
        assert client.get("/api/v1/runs/aggregate", params={"by": "tag"}).json()["groups"][0]["key"] == "pg"
