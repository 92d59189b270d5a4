"""The real app on a real database: a SQLite file in a temporary data directory, and a PostgreSQL
database of its own where a server can be had (every test here runs on both)."""

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.settings import Settings


@pytest.fixture
def settings(tmp_path, database_url):
    return Settings.from_environment(tmp_path / "data", database_url)


@pytest.fixture
def client(settings, compute):
    with TestClient(create_app(settings, compute=compute)) as test_client:
        yield test_client


@pytest.fixture
def auth(settings, client):
    token = (settings.data_dir / "api_token").read_text().strip()
    return {"Authorization": f"Bearer {token}"}
