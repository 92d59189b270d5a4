"""The service answers before the kernels load: building the API imports no numba, scipy, plotting,
cluster or 3D-view code (they load with the first simulation, or in the background)."""

import json
import subprocess
import sys

HEAVY = ("numba", "scipy", "matplotlib", "dask", "distributed", "viser")


def test_the_api_loads_no_kernels_plotting_cluster_or_view(tmp_path):
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
    assert "fastapi" in modules and "backend.services.simulation" in modules, "the probe built the app"
    assert [name for name in HEAVY if name in modules] == []
