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
