"""scripts/batch_trials_example.py, the README's client example: on a failure it leaves nothing
behind (issue 40: a first run that timed out left an empty experiment), and the service's own
message reaches the person running it."""

import json

import httpx
import pytest

from parkourlab import Client, ServiceUnavailable
from scripts import batch_trials_example

URL = "http://127.0.0.1:8000"
TOO_LONG = "the computation took longer than 60 s and was stopped"


class SecondRunFails:
    """A service whose first POST /runs succeeds and whose second answers 503; records the rest."""

    def __init__(self) -> None:
        self.runs: list[int] = []
        self.deleted: list[str] = []

    def __call__(self, request: httpx.Request) -> httpx.Response:
        method, path = request.method, request.url.path
        if path == "/api/v1/health":
            return httpx.Response(200, json={"status": "ok", "warming": [], "database": "sqlite", "code_version": "x"})
        if (method, path) == ("POST", "/api/v1/experiments"):
            return httpx.Response(201, json={"id": 5, "name": json.loads(request.content)["name"]})
        if (method, path) == ("POST", "/api/v1/runs"):
            if self.runs:
                return httpx.Response(503, json={"detail": TOO_LONG})
            self.runs.append(1)
            return httpx.Response(201, json={"id": 1})
        if (method, path) == ("GET", "/api/v1/runs"):
            assert request.url.params["experiment_id"] == "5"
            return httpx.Response(200, json={"items": [{"id": run} for run in self.runs], "next_cursor": None})
        if method == "DELETE":
            self.deleted.append(path)
            return httpx.Response(204)
        return httpx.Response(404, json={"detail": f"{method} {path} is not in this test's service"})


def test_a_failing_batch_deletes_what_it_made_and_shows_the_services_message(monkeypatch):
    service = SecondRunFails()
    transport = httpx.MockTransport(service)
    monkeypatch.setattr(batch_trials_example, "Client", lambda: Client(URL, token="t", transport=transport))
    with pytest.raises(ServiceUnavailable, match=f"POST /api/v1/runs: 503 service unavailable: {TOO_LONG}"):
        batch_trials_example.main()
    assert service.deleted == ["/api/v1/runs/1", "/api/v1/experiments/5"], "the run, then the experiment it was in"
