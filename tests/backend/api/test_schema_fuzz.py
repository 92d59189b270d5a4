"""Schemathesis against the OpenAPI schema: generated requests never get a 5xx, and every answer's
status is one the document lists for its operation (backend/api/statuses.py)."""

import os
import tempfile
from pathlib import Path

import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.specs.openapi.checks import content_type_conformance, status_code_conformance

from backend.api.app import create_app
from backend.api.token_file import api_token
from backend.settings import Settings
from backend.store.database import make_engine, migrate
from backend.workers.pools import Compute

pytestmark = pytest.mark.slow  # a few hundred generated requests

EXAMPLES = int(os.environ.get("PARKOUR_FUZZ_EXAMPLES", "20"))  # per endpoint; 300 for a deep pass
_DATA = Path(tempfile.mkdtemp(prefix="parkourlab-fuzz-"))
_SETTINGS = Settings.from_environment(_DATA)
migrate(make_engine(_SETTINGS.database_url))
_TOKEN, _ = api_token(_DATA)
# Jobs are stored but not run here (no runner), so fuzzed specs cost no compute.
# The robot's endpoints open links to real devices and sockets: tests/backend/api/routes/test_robot.py
# drives them against the virtual robot instead of fuzzing them. Without the 3D view (it is the
# frontend's, started by `parkour serve`) its endpoints answer 503 by design;
# tests/frontend/viewer/test_view.py drives them with a real view.
# Schemathesis runs the app's lifespan for every case: the app borrows worker pools that outlive it,
# or each case would start fresh worker processes.
_COMPUTE = Compute()
schema = schemathesis.openapi.from_asgi(
    "/openapi.json", create_app(_SETTINGS, run_jobs=False, compute=_COMPUTE)
).exclude(path_regex=r"^/api/v1/(robot|view)|/share\.html$")


@pytest.fixture(scope="module", autouse=True)
def _stop_workers():
    yield
    _COMPUTE.close()


@schema.parametrize()
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
def test_no_server_errors_and_only_documented_statuses(case):
    response = case.call(headers={"Authorization": f"Bearer {_TOKEN}"})
    assert response.status_code < 500, (
        f"{case.method} {case.formatted_path}: {response.status_code} {response.text[:300]}"
    )
    case.validate_response(response, checks=[status_code_conformance, content_type_conformance])
