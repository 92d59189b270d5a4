"""The 3D view inside the service: a real viser server on a free port, and headless browsers
(tests/frontend/viewer/headless.py) whose GUI is driven from Python as its callbacks would drive it;
and a private viser server (``server``) for the tests that draw on a scene of their own.
"""

import pytest
import viser
from fastapi.testclient import TestClient

from backend.api.app import create_app
from backend.settings import Settings
from frontend.viewer.app import ClimbView
from tests.frontend.viewer.headless import HeadlessViewer
from tests.frontend.viewer.view_service import wait_for


@pytest.fixture
def service(tmp_path):
    settings = Settings.from_environment(tmp_path / "data")
    app = create_app(settings, view_factory=lambda context: ClimbView(context, port=0))
    with TestClient(app) as client:
        token = (settings.data_dir / "api_token").read_text().strip()
        view = app.state.view_starter.wait(60)  # built in the background, after start-up
        assert view is not None, app.state.view_starter.unavailable_reason
        yield client, {"Authorization": f"Bearer {token}"}, view


@pytest.fixture
def browsers(service):
    """``open(viewer)``: a headless browser's view of the service's 3D view, and its session."""
    _client, _auth, view = service
    opened = []

    def open_view(viewer: str | None = None):
        before = set(view.sessions)
        opened.append(HeadlessViewer(view.server.get_port(), viewer))
        wait_for(lambda: set(view.sessions) - before)
        (client_id,) = set(view.sessions) - before
        return opened[-1], view.sessions[client_id]

    yield open_view
    for browser in opened:
        browser.close()


@pytest.fixture
def server():
    """A private viser server on a free port, its scene empty: for drawing without the service."""
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield server
    server.stop()
