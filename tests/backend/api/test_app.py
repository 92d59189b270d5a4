"""The service as ``create_app`` assembles it (backend/api/app.py): it answers before the kernels load,
keeps the data directory's token and e-stop latch, mounts every router and the panel, and bounds
the request threads once it runs."""

import importlib
import json
import pkgutil
import subprocess
import sys

import anyio.to_thread
import pytest
from fastapi.routing import APIRoute, iter_route_contexts
from fastapi.testclient import TestClient

from backend.api import routes
from backend.api.app import LATCH_FILE, REQUEST_THREADS, ROUTERS, create_app

HEAVY = ("numba", "scipy", "matplotlib", "dask", "distributed", "viser")


@pytest.fixture
def database_url():
    return None  # SQLite: nothing here depends on the database


def test_the_api_loads_no_kernels_plotting_cluster_or_view(tmp_path):
    """The service answers before the kernels load: building the API imports no numba, scipy,
    plotting, cluster or 3D-view code (they load with the first simulation, or in the background)."""
    probe = (
        "import json, sys\n"
        "from pathlib import Path\n"
        "from backend.api.app import create_app\n"
        "from backend.settings import Settings\n"
        "create_app(Settings.from_environment(Path(sys.argv[1])))\n"
        "print(json.dumps(sorted(sys.modules)))"
    )
    result = subprocess.run([sys.executable, "-c", probe, str(tmp_path)], capture_output=True, text=True, check=True)
    modules = set(json.loads(result.stdout.splitlines()[-1]))
    assert "fastapi" in modules and "backend.services.quick_calls" in modules, "the probe built the app"
    assert [name for name in HEAVY if name in modules] == []


def test_the_token_and_the_estop_latch_are_the_data_directorys(settings, compute):
    app = create_app(settings, compute=compute, run_jobs=False)
    token = (settings.data_dir / "api_token").read_text().strip()
    assert app.state.token == token, "made at the first start"
    assert app.state.robot.latch.path == settings.data_dir / LATCH_FILE, "a held e-stop survives a restart"
    assert create_app(settings, compute=compute, run_jobs=False).state.token == token, "and kept after it"


def test_every_route_module_is_mounted(client):
    """A module added under backend/api/routes and forgotten in ROUTERS would serve nothing."""
    modules = [
        importlib.import_module(f"backend.api.routes.{info.name}") for info in pkgutil.iter_modules(routes.__path__)
    ]
    assert sorted(module.__name__ for module in modules) == sorted(module.__name__ for module in ROUTERS)
    served = {
        (route.path, method) for route in iter_route_contexts(client.app.routes) for method in route.methods or ()
    }
    for module in modules:
        for route in module.router.routes:
            if isinstance(route, APIRoute):
                assert {(route.path, method) for method in route.methods} <= served, f"{module.__name__}: {route.path}"


def test_the_panel_is_served_from_its_own_folder(client):
    page = client.get("/panel/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    assert "<script" in page.text
    assert client.get("/panel/no-such-file.js").status_code == 404


def test_a_running_service_bounds_its_request_threads(client):
    limit = client.portal.call(lambda: anyio.to_thread.current_default_thread_limiter().total_tokens)
    assert limit == REQUEST_THREADS


def test_jobs_are_run_unless_the_app_is_told_not_to(settings, compute, client):
    assert client.app.state.runner is not None
    with TestClient(create_app(settings, compute=compute, run_jobs=False)) as reader:
        assert reader.app.state.runner is None
        assert reader.get("/api/v1/health").json()["status"] == "ok"
