"""docker-compose.yml: the service with a Dask scheduler and worker, Postgres as an opt-in profile."""

import shutil
import subprocess
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]


def test_compose_file_declares_the_stack():
    compose = yaml.safe_load((ROOT / "docker-compose.yml").read_text())
    services = compose["services"]
    assert {"parkourlab", "scheduler", "worker", "postgres"} <= set(services)
    assert services["postgres"]["profiles"] == ["postgres"], "Postgres is opt-in"
    assert all(port.startswith("127.0.0.1:") for port in services["parkourlab"]["ports"]), "localhost only"
    assert "--nthreads" in services["worker"]["command"] and "1" in services["worker"]["command"]
    assert (ROOT / "Dockerfile").exists()


@pytest.mark.skipif(shutil.which("docker-compose") is None, reason="docker-compose (Debian package) not installed")
def test_compose_file_validates():
    subprocess.run(["docker-compose", "config", "-q"], cwd=ROOT, check=True, timeout=60)


def test_the_image_copies_every_package_the_project_installs():
    """The console script lives in cli/: an image without it has no ``parkour`` (it once lacked it)."""
    import tomllib

    packages = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]["find"]
    wanted = {pattern.rstrip("*") for pattern in packages["include"]}
    copied = {line.split()[1] for line in (ROOT / "Dockerfile").read_text().splitlines() if line.startswith("COPY ")}
    assert wanted <= copied, f"the Dockerfile does not COPY {sorted(wanted - copied)}"
