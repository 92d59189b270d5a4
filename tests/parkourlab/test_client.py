"""parkourlab/client.py against the real service (tests/parkourlab/conftest.py: ``parkour serve`` in a
subprocess on a free port with a fresh SQLite data directory, started once for the session).

Covered: paging through more runs than a page holds (keyset and offset sorts), filters, edits,
experiments, the error types with the API's status and field messages (422, 401, 404, 409,
connection refused), exports to files, and that importing the client loads none of the project.
Jobs: test_jobs.py; DataFrames: test_frames.py."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest

from parkourlab import (
    ApiError,
    Client,
    Conflict,
    InvalidRequest,
    NotFound,
    ServiceUnreachable,
    Unauthorized,
)
from tests.helpers import free_port
from tests.parkourlab.conftest import START, ZETA0S

PAGE = 3


def test_runs_yields_every_page(client, paging_runs):
    first = client.runs_page(limit=PAGE, tag="paging")
    assert len(first["items"]) == PAGE and first["next_cursor"] is not None, "one page holds only three"
    listed = list(client.runs(tag="paging", page_size=PAGE))
    assert [run["id"] for run in listed] == sorted((run["id"] for run in paging_runs), reverse=True)
    oldest_first = list(client.runs(tag="paging", page_size=PAGE, sort="id"))
    assert [run["id"] for run in oldest_first] == [run["id"] for run in paging_runs]


def test_runs_pages_by_offset_for_other_sorts(client, paging_runs):
    best_first = list(client.runs(tag="paging", page_size=PAGE, sort="-climb"))
    assert len(best_first) == len(paging_runs)
    climbs = [run["climb"] for run in best_first]
    assert climbs == sorted(climbs, reverse=True)


def test_runs_filters(client, paging_runs):
    chosen = list(client.runs(tag="paging", zeta0_min=0.855, zeta0_max=0.885, page_size=PAGE))
    assert sorted(run["controls"][0][1] for run in chosen) == [0.86, 0.87, 0.88]
    experiment_id = paging_runs[0]["experiment_id"]
    assert len(list(client.runs(experiment_id=experiment_id))) == len(ZETA0S)
    assert list(client.runs(tag="no-such-tag")) == []
    with pytest.raises(TypeError, match="zeta_min"):
        client.runs(zeta_min=0.8)  # a misspelt filter the API would ignore: refused before any request


def test_run_detail_edit_and_delete(client):
    run = client.create_run([(30, 0.9)], {"xdot": -0.93, "ydot": -0.17}, jumps=3, trajectory_rate=20)
    assert client.run(run["id"])["results"]["rises"] == run["results"]["rises"]
    assert "y" in client.trajectory(run["id"])["columns"]
    edited = client.update_run(run["id"], tags=["edited"], notes="checked by hand")
    assert (edited["tags"], edited["notes"]) == (["edited"], "checked by hand")
    assert client.update_run(run["id"], notes="")["tags"] == ["edited"], "tags left out stay"
    client.delete_run(run["id"])
    with pytest.raises(NotFound):
        client.run(run["id"])


def test_aggregate_and_compare(client, paging_runs):
    groups = client.aggregate("zeta0", tag="paging")["groups"]
    assert sorted(group["key"] for group in groups) == ZETA0S
    comparison = client.compare([paging_runs[0]["id"], paging_runs[1]["id"]])
    assert "leg0.zeta0" in comparison["differing"]


def test_experiments(client, paging_runs):
    experiment_id = paging_runs[0]["experiment_id"]
    assert client.experiment(experiment_id)["runs"] == len(ZETA0S)
    renamed = client.update_experiment(experiment_id, notes="seven levels")
    assert (renamed["name"], renamed["notes"]) == ("paging", "seven levels")
    assert experiment_id in [experiment["id"] for experiment in client.experiments(page_size=1)]
    with pytest.raises(Conflict) as refused:
        client.delete_experiment(experiment_id)
    assert refused.value.status == 409 and "runs" in str(refused.value)


def test_invalid_request_names_the_field_and_its_range(client):
    with pytest.raises(InvalidRequest) as bad:
        client.create_run([(30, 1.2)], START)
    error = bad.value
    assert error.status == 422 and isinstance(error, ValueError)
    assert error.errors == [{"field": "controls[0].zeta0", "message": "Input should be less than 1 (got 1.2)"}]
    assert "controls[0].zeta0: Input should be less than 1" in str(error)
    with pytest.raises(InvalidRequest, match=r"limit: Input should be less than or equal to 500"):
        client.runs_page(limit=900)
    with pytest.raises(InvalidRequest, match=r"model\.preset: unknown preset 'nope'"):
        client.create_run([(30, 0.9)], START, model={"preset": "nope"})


def test_unauthorized_without_the_token(service, tmp_path, monkeypatch):
    url, _ = service
    with Client(url, token="not-the-token") as wrong, pytest.raises(Unauthorized) as refused:
        wrong.create_experiment("refused")
    assert refused.value.status == 401 and "bearer token" in str(refused.value)
    monkeypatch.delenv("PARKOUR_API_TOKEN", raising=False)
    monkeypatch.setenv("PARKOUR_DATA_DIR", str(tmp_path))  # no api_token there
    with Client(url) as anonymous:
        assert anonymous.health()["status"] == "ok", "reads need no token"
        assert not anonymous.token_accepted()
        with pytest.raises(Unauthorized, match="PARKOUR_API_TOKEN"):
            anonymous.submit_mjtf([0.9])


def test_token_from_the_environment(service, monkeypatch):
    url, token = service
    monkeypatch.setenv("PARKOUR_API_TOKEN", token)
    with Client(url) as client:
        assert client.token_accepted()


def test_not_found(client):
    with pytest.raises(NotFound) as missing:
        client.run(2_000_000)
    assert missing.value.status == 404 and missing.value.errors == [
        {"field": "", "message": "run 2000000 does not exist"}
    ]
    with pytest.raises(NotFound):
        client.job(2_000_000)
    assert issubclass(NotFound, ApiError)


def test_connection_refused_names_the_url():
    url = f"http://127.0.0.1:{free_port()}"
    with Client(url) as client, pytest.raises(ServiceUnreachable, match="connection refused") as refused:
        client.health()
    assert url in str(refused.value) and isinstance(refused.value, ConnectionError)


def test_exports_to_files(client, paging_runs, tmp_path):
    written = client.export_runs(tmp_path / "runs.csv", tag="paging")
    with written.open(newline="") as file:
        rows = list(csv.DictReader(file))
    assert sorted(float(row["leg0.zeta0"]) for row in rows) == ZETA0S
    records = json.loads(client.export_runs(tmp_path / "runs.json", tag="paging", zeta0_min=0.895).read_text())
    assert [record["leg0.zeta0"] for record in records] == [0.9]
    target = tmp_path / "sim.mcap"
    with pytest.raises(Conflict, match="sim run stored without its path"):
        client.export_mcap(paging_runs[0]["id"], target)
    assert list(tmp_path.glob("sim.mcap*")) == [], "a refused download leaves no file"


def test_the_client_closes_its_connections(service):
    with Client(service[0]) as client:
        client.health()
    assert client._http.client.is_closed


def test_importing_the_client_loads_none_of_the_project():
    """A script on another machine needs only parkourlab, httpx and rich."""
    heavy = ("sim_core", "experiments", "backend", "frontend", "cli", "numpy", "pandas", "fastapi", "sqlalchemy")
    code = f"import sys, parkourlab; print([m for m in sys.modules if m.split('.')[0] in {heavy!r}])"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "[]"


def test_the_controllers_are_the_services_registry(client):
    from sim_core.control.registry import LAWS

    assert [law["name"] for law in client.controllers()] == list(LAWS)
