"""What the backend's tests below the API share: a real, migrated SQLite file in a temporary
directory, and sessions on it (the API's tests build a whole app instead: tests/backend/api)."""

import pytest

from backend.store.database import make_engine, migrate, session_factory, sqlite_url


@pytest.fixture
def sessions(tmp_path):
    """The session factory the service hands its parts (``sessionmaker``, expire_on_commit off)."""
    engine = make_engine(sqlite_url(tmp_path))
    migrate(engine)
    yield session_factory(engine)
    engine.dispose()


@pytest.fixture
def session(sessions):
    with sessions() as session:
        yield session
