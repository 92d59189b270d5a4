"""``parkour`` starts at once: listing commands and their options loads none of the heavy packages.

Imports, not seconds, are asserted (the machines are shared and noisy); scripts/bench_startup.py
measures the times, as ratios to the numpy import.
"""

import json
import subprocess
import sys

import pytest

# Loaded only when a command runs: the kernels, the optimiser, the store, the service, the cluster,
# plotting, the 3D view and the MCAP writer with its protobuf schemas.
HEAVY = ("numba", "scipy", "sqlalchemy", "alembic", "dask", "distributed", "matplotlib", "viser", "fastapi", "uvicorn",
         "mcap", "google.protobuf", "foxglove_schemas_protobuf")  # fmt: skip
COMMANDS = ("map", "trajectory", "fixed-point", "gaits", "basin", "sweep", "mjtf", "mfpt", "viability", "pid", "atlas")
COMMANDS += ("reproduce",)
COMMANDS += ("robot-sim", "export", "bench", "serve")
COMMANDS += ("world",)


def _imported_by(*argv: str) -> set[str]:
    probe = (
        "import json, runpy, sys\n"
        "sys.argv = ['parkour', *sys.argv[1:]]\n"
        "try:\n    runpy.run_module('cli', run_name='__main__')\n"
        "except SystemExit as done:\n    assert done.code in (0, None), done.code\n"
        "print(json.dumps(sorted(sys.modules)))"
    )
    result = subprocess.run([sys.executable, "-c", probe, *argv], capture_output=True, text=True, check=True)
    return set(json.loads(result.stdout.splitlines()[-1]))


def _heavy(modules: set[str]) -> list[str]:
    return [name for name in HEAVY if name in modules]


def test_the_command_list_loads_nothing_heavy():
    assert _heavy(_imported_by("--help")) == []


@pytest.mark.parametrize("command", COMMANDS)
def test_a_commands_options_load_nothing_heavy(command):
    assert _heavy(_imported_by(command, "--help")) == [], f"parkour {command} --help"


def test_the_map_loads_the_kernels_but_not_the_optimiser_store_or_service():
    modules = _imported_by("map", "--jumps", "2", "--state", "-0.93", "-0.17", "--json")
    assert "numba" in modules and "sim_core.model.stride" in modules, "the probe really ran the map"
    assert [name for name in ("scipy.optimize", *HEAVY[2:]) if name in modules] == []


def test_the_worlds_load_nothing_heavy(tmp_path):
    """A world is data (sim_core.world.world, files, named, random_world): numpy, no kernels."""
    for argv in (("world", "show", "staircase", "--json"), ("world", "random", "--out", str(tmp_path / "w.json"))):
        modules = _imported_by(*argv)
        assert "sim_core.world.named" in modules, "the probe really ran the command"
        assert _heavy(modules) == [], f"parkour {' '.join(argv)}"
