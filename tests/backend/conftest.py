"""What the backend's tests below the API share: a real, migrated SQLite file in a temporary
directory, and sessions on it (the API's tests build a whole app instead: tests/backend/api)."""

import pytest


@pytest.fixture
def session(sessions):
    with sessions() as session:
        yield session
